"""Parameter sweeps on Dask: the drop test over a grid of heights (the
paper's 5 to 100 mm in 5 mm steps by default), masses, materials or any
parameter of the model, or a Monte Carlo campaign over their scatter, at
any size: the client holds the plan, never the cases.

  fraccontact sweep                                   # the paper's heights, a local cluster
  fraccontact sweep --vary c=2000,6080,20000 --vary height=0.01:0.1:0.01
  fraccontact sweep --vary law=g1,hertz --vary t_end=0.05,0.2 --set impacts=3 --set g=9.81
  fraccontact sweep --monte-carlo 100000 --scatter k=0.05 --scatter c=10% --scheduler tcp://host:8786

NAME (--vary, --set, --scatter) is a parameter of the model, as
fraccontact.parameters() lists them (the FMU's variables v, m, R, E_i,
nu_i, E_s, nu_s, k, c, law, g1_nodes, dt_max, scene, g, gap0, the scheme and
the stop conditions t_end and impacts), or height (the drop height: v =
sqrt(2 g h)); - or _ alike: E_s or E-s, t_end or t-end. Real parameters
take a grid a:b:step or a list v1,v2, integer ones too; law, scene and
scheme also their words (law=g1,hertz,g1x). A name is given once: set
(--set), varied (--vary) or, in a Monte Carlo campaign, scattered around
its --set value (--scatter); height and v are one quantity, given once.

A grid a:b:step holds a + i step for i = 0, 1, ... while it does not pass
b, computed exactly from the numbers as typed (decimal) and then rounded
to the nearest double: 0.005:0.1:0.005 gives 0.005, 0.01, ..., 0.035, ...,
0.1, and b is in the grid when it is a + i step exactly. A grid's impacts
are every combination of its --vary values, the last varying fastest.

A material (R, E_i, nu_i, E_s, nu_s) acts only through the Hertz constant
it gives when k = 0: the library's default k (the paper's fitted one) wins
over it. To sweep a material, --set k=0 --vary E_s=1e9,2e9; the sweep
warns, with the library's message, when a value it is given has no effect.

The default law: g1, the library's own (the G1 history sum, the model the
README describes); --set law=hertz for the closed form.

Monte Carlo: --monte-carlo N (N >= 1) draws N impacts instead of a grid
(no --vary beside it; --scatter and --seed only with it). --scatter
NAME=S draws NAME log-normally, with mean its nominal value (--set
NAME=VALUE, else the library's default) and coefficient of variation S
(standard deviation / mean), a fraction (0.05) or a percentage (5%).
Log-normal, it stays positive at any S. Only real parameters with a
positive nominal value scatter: a relative scatter of zero (g, gap0 at
their defaults) or of a negative value means nothing, so those are refused,
as is a negative S. Impact i's draws come from the seed, the parameter and
i alone: the same on any cluster, whatever the workers and --batch.

Each Dask task computes its own cases (its slice of the grid, or its draws),
runs them in calls of the C library (as fraccontact.impacts does, a few
thousand cases a call) and writes them itself: no case passes through the client, whose memory does not grow
with the campaign. A campaign is refused before it starts when its output
would not fit in the space free at --out (8 bytes a value in Parquet, 25
in the CSV). Writes to --out:
  sweep.parquet/  a Parquet partition a task (part-000000.parquet, ...,
                  in case order): per impact the inputs varied or drawn,
                  then the run's figures as fraccontact.impact names them
                  (the first impact's t_onset, v_onset, F_peak, eps,
                  t_contact, x2_end, E_diss: NaN when none ended; impacts,
                  steps and k; NAME_result when NAME is also an input, as
                  impacts or k), and error, the library's message for a
                  case it refused (empty for the others);
  sweep.csv       the same rows, with --csv only;
  sweep.png       the results against the first varied name (a grid of
                  at most 100 000 impacts), or their histograms (Monte
                  Carlo);
  sweep.json      counts and times: impacts, failed, tasks, wall_seconds
                  and impacts_per_second (see below), task_seconds,
                  task_cpu_seconds and library_cpu_seconds (the time
                  inside the tasks, their CPU, and the CPU of their
                  library calls, summed), statistics_seconds; for Monte
                  Carlo also the mean, sample standard deviation and
                  5/50/95 % percentiles (numpy's linear interpolation,
                  within `bound`, given for each column: see below) of
                  every numeric column over the impacts that succeeded,
                  and printed too.
The workers write into a hidden folder under --out (made absolute: a
worker's working folder need not be this one), moved into place when the
sweep ends: a failed or interrupted sweep (Ctrl-C: exit status 130;
SIGTERM: 143) leaves nothing.

The statistics are reduced inside the tasks: each task summarises its
columns (count, mean, squared deviations; a histogram on bins of 2^-15 of
the column's range of order-preserving keys, finer within a binade than
across binades), the summaries merge on the workers, and the client reads
no partition. The mean and std are exact to rounding; each percentile lies
within `bound` of numpy's (the width of the bins it falls in: at most
2^-13 of the column's largest value where its values lie within a factor of
two; exact for integers and constants). The statistics are the same bits on
any cluster.

Runs on a local Dask cluster, by default one worker of --workers threads in
the process that runs the sweep (this command's, or that of a program
calling sweep.main; the library's calls and the Parquet writes release
Python's GIL; default: the CPUs), or --workers processes with --processes;
or on any running Dask scheduler (--scheduler ADDRESS, refused when none
answers there within 5 s), whose workers must import fraccontact (pip
install '.[sweep]') and see --out (one machine, or a shared file system).
A task whose worker dies runs again on another: the results are the same.
Every option is checked, and --out too, before the cluster starts. The wall
time and the impacts per second count the Dask tasks alone, from the first
given to the last finished (before, each worker has imported the package).
"""

from .cli import main
from .options import CONNECT_TIMEOUT
from .tasks import RESULTS

__all__ = ["main", "CONNECT_TIMEOUT", "RESULTS"]
