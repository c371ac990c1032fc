"""Tests of arrange_up.parallel: serial, local-process and Dask runners."""

from __future__ import annotations

import os
import sys
import time

import pytest

from arrange_up import parallel
from arrange_up.parallel import (
    BackendUnavailableError,
    LocalRunner,
    RunnerConfig,
    SerialRunner,
    auto_chunksize,
    get_runner,
)


def _square(x: int) -> int:
    return x * x


def _pid(_: int) -> int:
    time.sleep(0.01)
    return os.getpid()


def _boom(x: int) -> int:
    if x == 5:
        raise RuntimeError("rollout 5 broke")
    return x


def test_serial_runner_maps_in_order():
    runner = get_runner("local", workers=1)
    assert isinstance(runner, SerialRunner) and runner.workers == 1
    assert list(runner.map(_square, range(5), chunksize=3)) == [(i, i * i) for i in range(5)]


def test_local_runner_yields_every_item_once_and_reuses_its_pool():
    runner = get_runner("local", workers=2)
    assert isinstance(runner, LocalRunner) and runner.workers == 2
    pairs = list(runner.map(_square, range(23), chunksize=4))
    assert sorted(pairs) == [(i, i * i) for i in range(23)]
    first = {pid for _, pid in runner.map(_pid, range(20), chunksize=2)}
    second = {pid for _, pid in get_runner("local", workers=2).map(_pid, range(20), chunksize=2)}
    assert os.getpid() not in first
    assert second == first  # the same worker processes: no new start-up


def test_the_pool_is_the_one_the_particle_semantics_use():
    # one worker pool per process: the runners', and the particle semantics' (the planner's
    # and, through it, the fixture repair's)
    from arrange_up.io.domains import load
    from arrange_up.transitions.particles import ParticleSemantics

    semantics = ParticleSemantics(load("blocks-2"), particles=4, workers=2)
    theirs = semantics._pool()
    assert theirs is parallel.local_executor(2)
    before = set(theirs.map(_pid, range(8)))
    ours = {pid for _, pid in get_runner("local", workers=2).map(_pid, range(8), chunksize=1)}
    assert before == ours


def test_errors_in_workers_reach_the_caller():
    with pytest.raises(RuntimeError, match="rollout 5 broke"):
        list(get_runner("local", workers=2).map(_boom, range(10), chunksize=2))


def test_bad_arguments():
    with pytest.raises(ValueError, match="unknown backend"):
        get_runner("cloud")
    with pytest.raises(ValueError, match="workers"):
        get_runner("local", workers=0)
    with pytest.raises(ValueError, match="needs the dask backend"):
        get_runner("local", scheduler="tcp://localhost:8786")
    with pytest.raises(ValueError, match="chunksize"):
        list(SerialRunner().map(_square, [1], chunksize=0))
    assert parallel.available_cores() >= 1


def test_auto_chunksize():
    assert auto_chunksize(1000, 2) == 25
    assert auto_chunksize(20, 2) == 3
    assert auto_chunksize(3, 8) == 1
    assert auto_chunksize(0, 2) == 1


def test_missing_dask_gives_an_install_hint(monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)
    with pytest.raises(BackendUnavailableError, match=r'pip install "arrange-up\[dask\]"'):
        parallel.DaskRunner(workers=2)


def _die_once(marker: str, item: int) -> int:
    if not os.path.exists(marker):
        open(marker, "w").close()
        os._exit(1)  # the worker is lost with its task (and the context it held)
    return item + 1


def test_dask_local_cluster_matches_local_processes(tmp_path):
    pytest.importorskip("distributed")
    from arrange_up.evaluation.evaluate import evaluate_plan
    from arrange_up.io.domains import load
    from arrange_up.planning.planner import plan

    problem = load("blocks-2")
    actions = plan(problem, semantics="deterministic", seed=0).actions
    try:
        runner = get_runner("dask", workers=2)
        assert runner.workers == 2 and get_runner("dask", workers=2) is runner
        assert sorted(runner.map(_square, range(7), chunksize=2)) == [(i, i * i) for i in range(7)]
        on_dask = evaluate_plan(
            problem, actions, rollouts=20, seed=0, runner=RunnerConfig(workers=2, backend="dask")
        )
        # a session's task whose worker dies with it is run again: the same answer
        marker = tmp_path / "died"
        assert runner.session(_die_once, str(marker)).submit(41).result() == 42
        assert marker.exists()
    finally:
        parallel.shutdown()
    local = evaluate_plan(problem, actions, rollouts=20, seed=0, runner=RunnerConfig(workers=2))
    assert on_dask == local
    assert on_dask.backend == "dask" and on_dask.workers == 2


_ORPHANS = """
import os, sys, time
from arrange_up.parallel import LocalRunner
from tests.test_parallel import _pid
pids = {pid for _, pid in LocalRunner(2).map(_pid, range(40), chunksize=1)}
print(" ".join(map(str, sorted(pids))), flush=True)
time.sleep(60)
"""


def _alive(pid: int) -> bool:
    """Whether process ``pid`` runs (a zombie nobody reaps counts as ended)."""
    try:
        with open(f"/proc/{pid}/stat") as handle:
            return handle.read().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False
    except OSError:  # pragma: no cover - no /proc: ask the kernel
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return False
        return True


def _alive_after(pids: list[int], seconds: float) -> list[int]:
    """The processes of ``pids`` still running once all have ended or ``seconds`` passed."""
    deadline = time.monotonic() + seconds
    while any(_alive(pid) for pid in pids) and time.monotonic() < deadline:
        time.sleep(0.1)
    return [pid for pid in pids if _alive(pid)]


@pytest.mark.skipif(sys.platform == "win32", reason="orphans keep their parent pid on Windows")
def test_workers_end_when_their_parent_is_killed():
    # a SIGKILLed parent cannot stop its pool; its workers lived on for tens of seconds
    import signal
    import subprocess
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(root), os.environ.get("PYTHONPATH", "")]),
    }
    parent = subprocess.Popen(
        [sys.executable, "-c", _ORPHANS], stdout=subprocess.PIPE, text=True, cwd=root, env=env
    )
    try:
        workers = [int(pid) for pid in parent.stdout.readline().split()]
        assert len(workers) == 2 and all(_alive(pid) for pid in workers)
    finally:
        parent.send_signal(signal.SIGKILL)
        parent.wait()
    assert not _alive_after(workers, 5.0)


_ORPHANS_AT_START = """
import os, time
from arrange_up.parallel import local_executor
executor = local_executor(2)
futures = [executor.submit(time.sleep, 5) for _ in range(4)]
time.sleep(0.2)  # the workers are still importing: their initializer has not run
me, children = os.getpid(), []
for pid in filter(str.isdigit, os.listdir("/proc")):
    try:
        with open(f"/proc/{pid}/stat") as handle:
            if int(handle.read().rsplit(")", 1)[1].split()[1]) == me:
                children.append(pid)
    except OSError:
        pass
print(" ".join(children), flush=True)
time.sleep(60)
"""


@pytest.mark.skipif(not os.path.isdir("/proc"), reason="lists the parent's children in /proc")
def test_workers_end_when_their_parent_is_killed_while_they_start():
    # killed 0.2 s after start, before the workers' initializer ran: they lived 40-50 s
    import signal
    import subprocess
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    parent = subprocess.Popen(
        [sys.executable, "-c", _ORPHANS_AT_START], stdout=subprocess.PIPE, text=True, cwd=root
    )
    try:
        children = [int(pid) for pid in parent.stdout.readline().split()]
        assert len(children) >= 2
    finally:
        parent.send_signal(signal.SIGKILL)
        parent.wait()
    left = _alive_after(children, 10.0)
    for pid in left:  # do not leave them behind when the test fails
        os.kill(pid, signal.SIGKILL)
    assert not left
