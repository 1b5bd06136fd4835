"""A sweep's cases as arrays, computed where they run. The client holds a
plan (the axes of a grid, or a Monte Carlo campaign's seed and scatter) and
gives each task an index range; the task computes its own cases: a slice of
the grid from the indices, or its draws from the seed. Case i is the same
whatever the tasks and the workers."""

import math
from dataclasses import dataclass

import numpy as np

from .. import model

# Monte Carlo draws come in blocks of BLOCK cases, each from its own seed
# (the campaign's seed, the parameter, the block's number): a task draws the
# blocks its range touches, so that case i's values never depend on where
# the tasks begin and end.
BLOCK = 1 << 12
# Doubles hold every integer below 2^53 exactly: below it, a grid's
# numerators and its scale divide in floating point, correctly rounded.
EXACT = 1 << 53


def code(name, v):
    """A parameter's value as the library takes it (law=hertz -> 2)."""
    return model.WORDS[name].get(v, v) if name in model.WORDS and isinstance(v, str) else v


@dataclass(frozen=True)
class Steps:
    """start + i step for i < n, the decimals typed held exactly as
    first / scale and stride / scale; integer parameters stay integers."""
    first: int
    stride: int
    scale: int
    n: int
    integer: bool

    def __len__(self):
        return self.n

    def at(self, i):
        """The values at the indices i, each the nearest double of the exact
        value (adding doubles would drift: 0.005 + 6 * 0.005 is
        0.034999999999999996)."""
        if abs(self.first) + self.stride * (self.n - 1) < EXACT and self.scale < EXACT:
            numerators = self.first + i.astype(np.int64) * self.stride
            if self.integer:
                return numerators // self.scale
            return numerators.astype(np.float64) / self.scale  # both exact: one correctly rounded division
        exact = [(self.first + int(j) * self.stride) for j in i]
        if self.integer:
            return np.array([x // self.scale for x in exact], dtype=np.int64)
        return np.array([x / self.scale for x in exact])  # Python's int division rounds correctly


@dataclass(frozen=True)
class Values:
    """Values listed as typed (v1,v2,...), shown as typed and given to the
    library as its codes (law=hertz runs law 2)."""
    shown: tuple
    codes: tuple

    def __len__(self):
        return len(self.shown)

    def at(self, i):
        return np.asarray(self.shown)[i]

    def codes_at(self, i):
        return np.asarray(self.codes)[i]


@dataclass(frozen=True)
class Grid:
    """Every combination of the axes ((name, Steps or Values), ...), the
    last varying fastest."""
    axes: tuple

    @property
    def n(self):
        return math.prod(len(axis) for _, axis in self.axes)

    def inputs(self, start, stop):
        """({name: values as shown}, {name: values as the library takes
        them}) of cases start to stop - 1."""
        shape = tuple(len(axis) for _, axis in self.axes)
        indices = np.unravel_index(np.arange(start, stop, dtype=np.int64), shape)
        shown, given = {}, {}
        for (name, axis), i in zip(self.axes, indices):
            low = int(i.min())
            span = np.arange(low, int(i.max()) + 1)  # each value once, for the indices this task spans
            shown[name] = axis.at(span)[i - low]
            given[name] = axis.codes_at(span)[i - low] if isinstance(axis, Values) else shown[name]
        return shown, given


def log_normal(rng, mean, cv, n):
    """n draws with that mean and coefficient of variation: the exponential
    of a normal of variance ln(1 + cv^2) and mean ln(mean) - variance / 2."""
    variance = math.log1p(cv * cv)
    return rng.lognormal(math.log(mean) - variance / 2, math.sqrt(variance), n)


@dataclass(frozen=True)
class MonteCarlo:
    """n cases, each scattered parameter log-normal: scattered is ((name,
    stream, mean, cv), ...), stream the parameter's own number, so that its
    draws do not depend on which others scatter."""
    n: int
    seed: int
    scattered: tuple

    def draws(self, stream, mean, cv, start, stop):
        first, last = start // BLOCK, (stop - 1) // BLOCK
        blocks = [log_normal(np.random.default_rng(np.random.SeedSequence(self.seed, spawn_key=(stream, b))),
                             mean, cv, BLOCK) for b in range(first, last + 1)]
        return np.concatenate(blocks)[start - first * BLOCK:stop - first * BLOCK]

    def inputs(self, start, stop):
        shown = {name: self.draws(stream, mean, cv, start, stop) for name, stream, mean, cv in self.scattered}
        return shown, shown


# A task costs a fixed time beside its impacts (Dask's round trip, opening
# its Parquet file): TASK_MIN keeps that small against the cheapest impacts;
# TASK_MAX bounds a worker's memory (its arrays grow with its impacts), and
# TASKS leaves work to balance over several workers.
TASKS = 32
TASK_MIN = 20_000
TASK_MAX = 200_000


def task_size(n, batch):
    """Impacts per task: --batch, else a size that depends on n alone (never
    on the workers, so that the partitions are the same on any cluster):
    about TASKS tasks, each between TASK_MIN and TASK_MAX impacts."""
    return batch if batch is not None else min(max(math.ceil(n / TASKS), TASK_MIN), TASK_MAX)


def ranges(n, size):
    """(index, start, stop) of each task."""
    return ((i, start, min(start + size, n)) for i, start in enumerate(range(0, n, size)))
