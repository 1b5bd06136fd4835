"""What the commands' command lines share: errors on one line, and argparse
types that refuse a value with its option, the value and the rule."""

import argparse
import math
import re


class OneLineParser(argparse.ArgumentParser):
    """Errors as one line on stderr, exit status 2. A negative number in
    any notation (-1e-5 too, which argparse takes for an option) is a value."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-\.?\d")

    def error(self, message):
        self.exit(2, f"{self.prog}: {message} (see --help)\n")


def finite(text):
    """argparse type: a finite number."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number")
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text} is not a finite number")
    return value


def positive(text):
    """argparse type: a finite number > 0."""
    value = finite(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"{text} is not positive")
    return value
