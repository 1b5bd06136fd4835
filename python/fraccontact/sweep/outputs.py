"""What a sweep leaves in --out: the workers' partitions, gathered in a
hidden folder while the sweep runs, with sweep.csv (joined from the
workers' CSV parts, when asked), the plot and sweep.json beside them, all
moved into place at its end (a failed or interrupted sweep leaves
nothing). An older run's outputs are replaced, or removed where this run
writes none."""

import math
import os
import pathlib
import shutil
import tempfile
import threading

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from .. import atomic
from .options import FILES, PARTITIONS

# The most cases a grid's plot draws: the client reads their figures.
PLOT_LIMIT = 100_000
# The plotted results: (key, scale to the unit shown, what it is, unit).
PLOTTED = (("F_peak", 1, "peak force F_peak", "N"), ("eps", 1, "restitution coefficient eps", "1"),
           ("t_contact", 1e3, "contact time", "ms"), ("x2_end", 1e6, "permanent indentation", "µm"))


class Staging:
    """The hidden folder under --out the workers write into."""

    def __init__(self, out):
        self.out = out.absolute()  # the workers' working folder need not be this process's
        self.made = [p for p in (self.out, *self.out.parents) if not p.exists()]
        self.out.mkdir(parents=True, exist_ok=True)
        self.folder = pathlib.Path(tempfile.mkdtemp(dir=self.out, prefix=f".{PARTITIONS}."))

    def discard(self):
        """Removes what the sweep wrote: the hidden folder, and --out itself
        where the sweep made it."""
        shutil.rmtree(self.folder, ignore_errors=True)
        for folder in self.made:
            try:
                folder.rmdir()
            except OSError:
                break

    def commit(self, written):
        """Moves the files written (names) and the partitions into place,
        leftovers of tasks that a dead worker left half-written dropped, and
        removes the older run's files this one did not write."""
        for name in FILES:
            if name in written:
                os.replace(self.folder / name, self.out / name)
            elif (self.out / name).exists():
                (self.out / name).unlink()
        for leftover in self.folder.glob(".*.tmp"):
            leftover.unlink()
        os.chmod(self.folder, 0o755)  # mkdtemp's 0700 is for the hidden folder only
        final = self.out / PARTITIONS
        old = None
        if final.exists():
            old = pathlib.Path(tempfile.mkdtemp(dir=self.out, prefix=f".{PARTITIONS}.old."))
            os.replace(final, old / PARTITIONS)
        os.replace(self.folder, final)
        if old:
            shutil.rmtree(old)


def join_csv(parts, path):
    """The workers' CSV parts, in case order, as one file (one header), read
    and written a block at a time; the parts removed."""
    with atomic.replacing(path, "wb") as out:
        for i, part in enumerate(parts):
            with open(part, "rb") as f:
                header = f.readline()
                if i == 0:
                    out.write(header)
                shutil.copyfileobj(f, out, 1 << 20)
            os.unlink(part)


def succeeded_rows(files, columns):
    """The columns of the cases that ran, from the partitions."""
    import pyarrow.compute as pc  # a grid's plot alone reads the partitions
    tables = [pq.read_table(f, columns=columns + ["error"]) for f in files]
    table = pa.concat_tables(tables)
    return table.filter(pc.is_null(table.column("error"))).drop_columns(["error"])


def shown(v):
    return f"{v:g}" if isinstance(v, float) else str(v)


def pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def preload():
    """Imports matplotlib in the background while the client waits for its
    tasks: the plot comes after them."""
    threading.Thread(target=pyplot, daemon=True).start()


def figure(columns):
    return pyplot().subplots(*columns)


def plot(path, files, names, title):
    """Each plotted result against the first varied name, a line for each
    combination of the others (a grid of at most PLOT_LIMIT cases)."""
    keys = [key for key, *_ in PLOTTED]
    table = succeeded_rows(files, list(dict.fromkeys(names + keys)))
    x_name, others = names[0], names[1:]
    x = np.asarray(table.column(x_name).to_pylist())
    labels = zip(*[table.column(k).to_pylist() for k in others]) if others else [()] * len(x)
    members = {}
    for i, label in enumerate(labels):
        members.setdefault(label, []).append(i)
    groups = sorted(members)
    fig, axes = figure((2, 2))
    fig.set_size_inches(11, 7.5)
    for ax, (key, scale, what, unit) in zip(axes.flat, PLOTTED):
        y = table.column(key).to_numpy() * scale
        for g in groups:
            sel = np.array(members[g], dtype=int)
            sel = sel[np.argsort(x[sel], kind="stable")]
            legend = ", ".join(f"{k} = {shown(v)}" for k, v in zip(others, g)) or None
            ax.plot(x[sel] * 1e3 if x_name == "height" else x[sel], y[sel], marker=".", label=legend)
        ax.set(xlabel="drop height [mm]" if x_name == "height" else x_name, ylabel=f"{what} [{unit}]")
        ax.grid(alpha=0.3)
        if len(groups) > 1:
            ax.legend(fontsize=7)
    fig.suptitle(title)
    fig.tight_layout()
    atomic.save_figure(fig, path, dpi=100, metadata={"Software": None})


def histogram_bins(n):
    """sqrt(N) bins (5 to 50): enough to show the shape, few enough that
    each bin holds several impacts."""
    return int(np.clip(round(math.sqrt(n)), 5, 50))


def histograms(path, counted, stats, title):
    """A histogram of each plotted result (counted: {key: (counts, low,
    high)}, numpy's bins over [low, high]), its mean and 5/50/95 %
    percentiles marked."""
    fig, axes = figure((1, 4))
    fig.set_size_inches(17, 4.4)
    for ax, (key, scale, what, unit) in zip(axes, PLOTTED):
        ax.set(xlabel=f"{what} [{unit}]", ylabel="impacts")
        if key not in counted:
            continue
        counts, low, high = counted[key]
        edges = np.histogram_bin_edges([low, high], bins=len(counts), range=(low, high))
        ax.stairs(counts, edges * scale, fill=True, color="tab:blue", alpha=0.7)
        s = {k: v * scale for k, v in stats[key].items() if v is not None}
        u = "" if unit == "1" else f" {unit}"
        spread = f" ± {s['std']:.3g}{u} (std)" if "std" in s else u
        ax.axvline(s["mean"], color="k", label=f"mean {s['mean']:.4g}{spread}")
        ax.axvline(s["p50"], color="tab:red", ls="--", label=f"median {s['p50']:.4g}{u}")
        ax.axvline(s["p5"], color="tab:red", ls=":", label=f"5 / 95 %: {s['p5']:.4g} / {s['p95']:.4g}{u}")
        ax.axvline(s["p95"], color="tab:red", ls=":")
        ax.set_ylim(top=1.4 * ax.get_ylim()[1])  # room for the legend above the bars
        ax.legend(fontsize=7, loc="upper right")
    fig.suptitle(title)
    # Fixed margins: tight_layout would draw the figure once more to measure it.
    fig.subplots_adjust(left=0.05, right=0.99, bottom=0.13, top=0.88, wspace=0.3)
    atomic.save_figure(fig, path, dpi=100, metadata={"Software": None})


def print_statistics(stats):
    print(f"{'':<12}" + "".join(f"{h:>14}" for h in ("mean", "std", "5 %", "50 %", "95 %", "± percentiles")))
    for key, s in stats.items():
        print(f"{key:<12}" + "".join(f"{'-' if v is None else format(v, '.6g'):>14}" for v in s.values()))
