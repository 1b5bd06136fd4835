"""The sweep's options (fraccontact/sweep/options.py): what `fraccontact
sweep` decides before Dask starts is checked in-process, with the cluster
replaced by a failure (an option that is refused must be refused before
anything runs); the few behaviours that need a process or a cluster run
one each. The sizes it refuses: a grid or a Monte Carlo campaign whose
output the disk cannot hold, checked before anything runs; the grid's
values, options that would be ignored or contradict each other, the
output folder and the scheduler; what --help and docs/sweeps.md say."""

import os
import resource
import shutil
import signal
import subprocess
import sys
import time

import pytest

import fraccontact
from fraccontact import sweep
from fraccontact.sweep import cli, options

pytestmark = pytest.mark.skipif(os.environ.get("FRACCONTACT_SANITIZED") == "1",
                                reason="Dask workers under a preloaded sanitizer runtime")


class Started(Exception):
    """The sweep got as far as starting its cluster."""

    def __init__(self, args, plan):
        super().__init__("the sweep started")
        self.options, self.plan = args, plan


def every_case(plan):
    """The cases of a (small) plan, a dict each, as Python numbers."""
    shown, _ = plan.cases.inputs(0, plan.cases.n)
    columns = {name: x.tolist() for name, x in shown.items()}
    return [dict(zip(columns, row)) for row in zip(*columns.values())]


@pytest.fixture
def no_cluster(monkeypatch):
    """sweep.main stops where it would start Dask, with the options and the
    plan it would run."""
    def started(args, client, cluster, plan, *rest):
        raise Started(args, plan)
    monkeypatch.setattr(cli, "connect", lambda args: (None, None))
    monkeypatch.setattr(cli, "close", lambda client, cluster: None)
    monkeypatch.setattr(cli, "run", started)


def refusal(capsys, *args):
    """The exit status and the error line of a sweep that must be refused."""
    with pytest.raises(SystemExit) as e:
        sweep.main(list(args))
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return e.value.code, err.strip().splitlines()[-1]


def planned(tmp_path, *args):
    """The options and cases a sweep would run."""
    with pytest.raises(Started) as e:
        sweep.main([*args, "--out", str(tmp_path / "out")])
    return e.value.options, every_case(e.value.plan)


# ---------------------------------------------------------------- sizes: the disk's bound


def limited_sweep(*args):
    """The command line in a process limited to 2 GiB of address space, so
    that a grid built in memory fails there (MemoryError) instead of taking
    the machine's memory."""
    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))
    return subprocess.run([sys.executable, "-m", "fraccontact", "sweep", *args], capture_output=True, text=True,
                          preexec_fn=limit, timeout=120, env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))


def test_a_huge_grid_is_refused_before_it_is_built(tmp_path):
    """1e15 values: the axis is never built (the process has 2 GiB), and a
    grid whose output no disk here holds is refused, naming the size."""
    done = limited_sweep("--vary", "c=1:1e15:1", "--out", str(tmp_path / "out"))
    assert done.returncode == 2, done.stderr[-2000:]
    last = done.stderr.strip().splitlines()[-1]
    assert "--vary c=1:1e15:1: 1000000000000000 impacts would write about" in last and "free there" in last, last
    assert "Traceback" not in done.stderr and not (tmp_path / "out").exists()


def test_a_grid_whose_product_is_too_large_is_refused(no_cluster, tmp_path, capsys):
    """1e8 x 1e8 values, no axis built: the product is refused."""
    code, line = refusal(capsys, "--vary", "c=1:1e8:1", "--vary", "k=1e8:1.999e8:1", "--out", str(tmp_path))
    assert code == 2
    assert "--vary c=1:1e8:1 --vary k=1e8:1.999e8:1: a grid of 100000000 x 99900001 = 9990000100000000 impacts " \
           "would write about" in line, line


def test_a_huge_monte_carlo_is_refused(no_cluster, tmp_path, capsys):
    code, line = refusal(capsys, "--monte-carlo", str(10 ** 15), "--scatter", "c=0.1", "--out", str(tmp_path))
    assert code == 2 and "--monte-carlo 1000000000000000: 1000000000000000 impacts would write about" in line, line


@pytest.mark.parametrize("csv", [False, True])
def test_the_disk_bound_is_where_the_help_says(csv, no_cluster, tmp_path, capsys, monkeypatch):
    """10^8 impacts run when the disk holds their output: c
    and the 10 results (t_onset, v_onset, F_peak, eps, t_contact, x2_end,
    E_diss, impacts, steps, k) are 11 values an impact, 8 bytes each in
    Parquet and 25 more in the CSV; one byte less free is refused."""
    n = 10 ** 8
    need = n * 11 * (8 + (25 if csv else 0))
    args = ["--monte-carlo", str(n), "--scatter", "c=0.1"] + (["--csv"] if csv else [])
    for free in (need, need - 1):
        monkeypatch.setattr(options.shutil, "disk_usage", lambda path: shutil._ntuple_diskusage(2 * need, 0, free))
        if free == need:
            with pytest.raises(Started) as e:
                sweep.main(args + ["--out", str(tmp_path / "out")])
            assert e.value.plan.cases.n == n
        else:
            code, line = refusal(capsys, *args, "--out", str(tmp_path / "out"))
            assert code == 2 and f"--monte-carlo {n}: {n} impacts would write about" in line, line


def readme_sweep_section():
    page = open(os.path.join(os.path.dirname(__file__), "..", "docs", "sweeps.md")).read()
    return " ".join(page.split())


def help_text(capsys):
    with pytest.raises(SystemExit) as e:
        sweep.main(["--help"])
    assert e.value.code == 0
    return " ".join(capsys.readouterr().out.split())


def test_the_limits_are_stated_as_the_code_has_them(capsys):
    limit = f"({options.PARQUET_BYTES} bytes a value in Parquet, {options.CSV_BYTES} in the CSV)"
    text = help_text(capsys)
    assert limit in text and f"within {sweep.CONNECT_TIMEOUT} s" in text
    assert limit in readme_sweep_section() and f"within {sweep.CONNECT_TIMEOUT} s" in readme_sweep_section()


# ---------------------------------------------------------------- a material beside k


def test_a_material_beside_k_is_warned_of_once(no_cluster, tmp_path, capsys):
    """The library's own message, once on the client, for the first value
    without effect."""
    with pytest.raises(Started):
        sweep.main(["--vary", "E-s=1e9,2e9", "--out", str(tmp_path)])
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1, lines
    assert lines[0].endswith(f"warning: {fraccontact.warning(E_s=1e9)}"), lines
    assert "k = 3.299e+08 is given and wins" in lines[0]


def test_a_material_with_k_zero_is_not_warned_of(no_cluster, tmp_path, capsys):
    with pytest.raises(Started):
        sweep.main(["--set", "k=0", "--vary", "E-s=1e9,2e9", "--out", str(tmp_path)])
    assert capsys.readouterr().err == ""


def test_help_and_readme_say_how_to_sweep_a_material(capsys):
    assert "To sweep a material, --set k=0 --vary E_s=" in help_text(capsys)
    assert "to sweep a material, `--set k=0`" in readme_sweep_section()


def test_the_warning_is_printed_once_by_a_real_sweep(tmp_path):
    """A whole sweep on a local cluster: the client's one warning and no
    other (the workers' library calls stay quiet), and the rows are the
    same, as the warning says."""
    done = subprocess.run([sys.executable, "-m", "fraccontact", "sweep", "--vary", "E-s=1e9,2e9", "--set", "law=hertz",
                           "--set", "dt_max=1e-6", "--workers", "1", "--csv", "--out", str(tmp_path)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stderr.count("has no effect") == 1, done.stderr
    rows = (tmp_path / "sweep.csv").read_text().splitlines()
    assert len(rows) == 3 and rows[1].split(",")[1:] == rows[2].split(",")[1:]


# ---------------------------------------------------------------- the grid's values


@pytest.mark.parametrize("spec, expected", [
    ("tolerance=1e-12:4e-12:1.5e-12", [1e-12, 2.5e-12, 4e-12]),  # rounding to 12 decimals ran 1e-12, 3e-12, 4e-12
    ("gap0=0:4e-12:1.5e-12", [0.0, 1.5e-12, 3e-12]),  # rounding to 12 decimals ran 0, 2e-12, 3e-12
    ("R=1e-13:5e-13:1e-13", [1e-13, 2e-13, 3e-13, 4e-13, 5e-13]),
])
def test_small_grid_values_are_the_ones_asked_for(spec, expected, no_cluster, tmp_path):
    """Each value exactly the double of the decimal start + i step (the
    literals here), where rounding to 12 decimals merged or moved them."""
    _, cases = planned(tmp_path, "--vary", spec)
    name = spec.partition("=")[0]
    assert [case[name] for case in cases] == expected


@pytest.mark.parametrize("spec, expected", [
    ("height=0.005:0.1:0.005", [float(f"{5 * i}e-3") for i in range(1, 21)]),  # stop on the grid: included
    ("c=0.1:0.3:0.1", [0.1, 0.2, 0.3]),  # doubles would give 0.30000000000000004
    ("c=0:1:0.3", [0.0, 0.3, 0.6, 0.9]),  # stop off the grid: the last value before it
    ("c=2.5:2.5:1", [2.5]),
    ("g1_nodes=10:40:10", [10, 20, 30, 40]),
])
def test_grid_rule(spec, expected, no_cluster, tmp_path):
    """start + i step while it does not pass stop, exactly in decimal, each
    then the nearest double; integers stay integers."""
    _, cases = planned(tmp_path, "--vary", spec)
    got = [case[spec.partition("=")[0]] for case in cases]
    assert got == expected and [type(x) for x in got] == [type(x) for x in expected]


def test_a_step_doubles_cannot_resolve_is_refused(no_cluster, tmp_path, capsys):
    code, line = refusal(capsys, "--vary", "c=1:1.0000000000000002:1e-17", "--out", str(tmp_path))
    assert code == 2 and "--vary c=1:1.0000000000000002:1e-17" in line and "repeat" in line, line


# ---------------------------------------------------------------- options ignored or contradicting


@pytest.mark.parametrize("args, message", [
    (["--set", "height=0.02"], "--set height=0.02 without --vary"),
    (["--set", "v=1"], "--set v=1 without --vary"),
    (["--monte-carlo", "5", "--scatter", "c=0.1", "--vary", "k=1e8,2e8"], "--vary k=1e8,2e8 with --monte-carlo"),
    (["--scatter", "c=0.1"], "--scatter c=0.1 without --monte-carlo"),
    (["--monte-carlo", "0", "--scatter", "c=0.1"], "--monte-carlo 0: the number of impacts must be >= 1"),
    (["--monte-carlo", "-3", "--scatter", "c=0.1"], "--monte-carlo -3"),
    (["--set", "c=5000", "--vary", "c=3000,6080"], "--set c=5000 and --vary c=3000,6080: a parameter is either"),
    (["--vary", "c=1,2", "--vary", "c=3"], "--vary c=1,2 and --vary c=3: c is given twice"),
    (["--set", "c=1", "--set", "c=2"], "--set c=1 and --set c=2: c is given twice"),
    (["--set", "v=1", "--vary", "height=0.01,0.02"], "--vary height=0.01,0.02 and --set v=1: height sets v"),
    (["--seed", "3"], "--seed 3 without --monte-carlo"),
    (["--monte-carlo", "5", "--scatter", "c=0.1", "--seed", "-1"], "--seed -1"),
    (["--scheduler", "tcp://127.0.0.1:1", "--workers", "2"], "--workers 2 with --scheduler"),
    (["--workers", "100000"], "--workers 100000: a local cluster has 1 to"),
    (["--batch", "-1"], "--batch -1: impacts per Dask task, >= 1"),
    (["--batch", "0"], "--batch 0: impacts per Dask task, >= 1"),  # 26f430c took it
    (["--vary", "c=1:inf:1"], "--vary c=1:inf:1: a grid's start, stop and step are finite"),
])
def test_options_that_would_be_ignored_or_contradict_are_refused(args, message, no_cluster, tmp_path, capsys):
    code, line = refusal(capsys, *args, "--out", str(tmp_path / "out"))
    assert code == 2 and message in line, line
    assert not (tmp_path / "out").exists()


def test_a_set_height_with_a_grid_is_held(no_cluster, tmp_path):
    """What --set height says, beside a grid of something else: every case
    at that height."""
    args, cases = planned(tmp_path, "--set", "height=0.02", "--vary", "c=3000,6080")
    assert cases == [{"c": 3000.0}, {"c": 6080.0}] and args.fixed["height"] == 0.02


# ---------------------------------------------------------------- the output folder and the scheduler


@pytest.mark.parametrize("make, message", [
    (lambda tmp: "/dev/null", "--out /dev/null: not a folder"),
    (lambda tmp: (tmp / "file").write_text("x") and str(tmp / "file"), "not a folder"),
    (lambda tmp: (tmp / "file").write_text("x") and str(tmp / "file" / "sub"), "is not a folder"),
    (lambda tmp: (tmp / "out" / "sweep.csv").mkdir(parents=True) or str(tmp / "out"), "sweep.csv is a folder"),
], ids=["dev-null", "a-file", "under-a-file", "a-result-is-a-folder"])
def test_an_out_that_cannot_receive_the_results_is_refused_first(make, message, no_cluster, tmp_path, capsys):
    out = make(tmp_path)
    code, line = refusal(capsys, "--vary", "c=3000,6080", "--out", out)
    assert code == 2 and f"--out {out}" in line and message in line, line


def test_a_bad_scheduler_address_is_refused(tmp_path, capsys):
    code, line = refusal(capsys, "--scheduler", "localhost", "--out", str(tmp_path / "out"))
    assert code == 2 and "--scheduler localhost:" in line, line
    assert not (tmp_path / "out").exists()


def test_an_unreachable_scheduler_is_refused_quickly(tmp_path, capsys, monkeypatch):
    """Nothing listens on port 1: refused after the connect timeout (Dask's
    default is 30 s; 1 s here, to keep the test short), naming the address,
    nothing written."""
    monkeypatch.setattr(options, "CONNECT_TIMEOUT", 1)
    start = time.perf_counter()
    code, line = refusal(capsys, "--scheduler", "tcp://127.0.0.1:1", "--vary", "c=3000,6080",
                         "--out", str(tmp_path / "out"))
    assert time.perf_counter() - start < options.CONNECT_TIMEOUT + 5
    assert code == 2 and "--scheduler tcp://127.0.0.1:1: no Dask scheduler answered" in line, line
    assert not (tmp_path / "out").exists()


def test_the_drift_the_readme_shows():
    """docs/sweeps.md's example of what adding doubles gives, beside the grid's 0.035 (test_grid_rule)."""
    assert repr(0.005 + 6 * 0.005) == "0.034999999999999996" and "0.034999999999999996" in readme_sweep_section()


# ---------------------------------------------------------------- what --help and the docs say


def test_help_and_docs_say_where_the_local_workers_run(capsys):
    """The default cluster's threads run in the sweep's process (26f430c:
    "in its own process" in the docs, "in this process" in --help)."""
    where = "the process that runs the sweep (this command's, or that of a program calling"
    assert f"threads in {where} sweep.main" in help_text(capsys)
    assert f"with a thread per CPU, in {where} `sweep.main`)" in readme_sweep_section()
    assert "in its own process" not in readme_sweep_section()


def test_the_sweep_extra_installs_what_the_docs_read_the_partitions_with():
    """docs/sweeps.md reads the partitions with pyarrow or pandas: pip
    install '.[sweep]' installs both (26f430c: no pandas)."""
    import tomllib
    root = os.path.join(os.path.dirname(__file__), "..")
    with open(os.path.join(root, "pyproject.toml"), "rb") as f:
        extra = tomllib.load(f)["project"]["optional-dependencies"]["sweep"]
    for module in ("pyarrow.parquet.read_table", "pandas.read_parquet"):
        assert module in readme_sweep_section() and module.partition(".")[0] in extra, module


def test_help_and_docs_state_the_exit_statuses_of_a_signal(capsys):
    """128 + the signal, as a shell reports a process the signal ended
    (tests/test_sweep_scale.py sends them)."""
    interrupt, terminate = 128 + signal.SIGINT, 128 + signal.SIGTERM
    assert f"(Ctrl-C: exit status {interrupt}; SIGTERM: {terminate}) leaves nothing" in help_text(capsys)
    assert f"(Ctrl-C: exit status {interrupt}; SIGTERM, as `timeout` and batch systems send it: {terminate}) " \
           "leaves nothing" in readme_sweep_section()
