"""Result files written whole or not at all: each is written to a temporary
file beside its destination and renamed over it, so that an interrupted run
never leaves a half-written file that looks complete."""

import contextlib
import os
import pathlib
import tempfile


@contextlib.contextmanager
def replacing(path, mode="w", **kw):
    """open() for writing, with the file appearing at path only on success."""
    path = pathlib.Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, mode, **kw) as f:
            yield f
        os.chmod(tmp, 0o644)  # mkstemp's 0600 is for the temporary file only
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def write_text(path, text):
    with replacing(path) as f:
        f.write(text)


def save_figure(fig, path, **kw):
    with replacing(path, "wb") as f:
        fig.savefig(f, format=pathlib.Path(path).suffix[1:], **kw)
