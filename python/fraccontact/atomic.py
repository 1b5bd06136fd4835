"""Result files written whole or not at all: each is written to a temporary
file beside its destination and renamed over it, so that an interrupted run
never leaves a half-written file that looks complete, nor its temporary."""

import contextlib
import os
import pathlib
import signal
import tempfile
import threading


@contextlib.contextmanager
def _termination_raises():
    """SIGTERM's default action ends the process on the spot, skipping the
    cleanup of the temporary file: while one is open, SIGTERM raises
    SystemExit instead (exit status 143, as the default's shell status).
    Only where Python can take signals (the main thread) and only if nobody
    installed a handler of their own."""
    if threading.current_thread() is not threading.main_thread() \
            or signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL:
        yield
        return

    def terminate(signum, frame):
        raise SystemExit(128 + signum)
    previous = signal.signal(signal.SIGTERM, terminate)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


@contextlib.contextmanager
def replacing(path, mode="w", **kw):
    """open() for writing, with the file appearing at path only on success."""
    path = pathlib.Path(path)
    with _termination_raises():
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
