"""A progress bar on stderr for the long reports, shown only on a terminal
(a log gets the reports' own summary lines instead)."""

import sys


def progress(done, total, what=""):
    """Draws the bar at done of total; done == total ends its line."""
    if not sys.stderr.isatty():
        return
    bar = "#" * int(30 * done / max(total, 1))
    print(f"\r[{bar:<30}] {done}/{total} {what:<60.60}", end="\n" if done >= total else "", file=sys.stderr,
          flush=True)
