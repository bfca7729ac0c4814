"""Ctrl-C stops a run cleanly: KeyboardInterrupt, raised promptly, with where the run stopped."""

import _thread
import threading

import pytest

import piezocontact as pc


def test_ctrl_c_stops_a_long_run_at_its_next_check():
    # some 15 s to its end on this project's machines: the first-order solver with a full
    # solve per step
    scene = pc.Scene.load("paper", {"mesh.n": 64, "solver.strategy": "uzawa-direct"})
    timer = threading.Timer(0.5, _thread.interrupt_main)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt) as info:
            pc.run(scene)
    finally:
        timer.cancel()
    # the solve itself stopped (it did not run to its end and then see the signal)
    notes = getattr(info.value, "__notes__", [])
    assert any("the run stopped" in n and "cancelled" in n for n in notes), notes
    # and the next run on this thread is not cancelled by the last one's flag
    assert pc.run(pc.Scene.load("paper", {"mesh.n": 4})).report["residuals"]["converged_to_tolerance"]


def test_ctrl_c_during_a_step_stops_the_run_after_that_step():
    # paper-3d at n = 20: set-up and assembly in some 0.2 s, then a factorisation of some 3 s,
    # which is not cut; the run stops after it, before the contact solve
    lines = []
    scene = pc.Scene.load("paper-3d", {"mesh.n": 20})
    timer = threading.Timer(0.6, _thread.interrupt_main)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt) as info:
            pc.run(scene, progress=lines.append)
    finally:
        timer.cancel()
    notes = getattr(info.value, "__notes__", [])
    assert any("the run stopped: interrupted after" in n for n in notes), notes
    assert not any(line.strip().startswith("newton") for line in lines), lines


def test_an_exception_in_the_progress_callback_stops_the_run():
    class Stop(Exception):
        pass

    def progress(line):
        if line.strip().startswith("newton"):
            raise Stop(line)

    with pytest.raises(Stop) as info:
        pc.run(pc.Scene.load("paper", {"mesh.n": 16}), progress=progress)
    # stopped at the first Newton step's line: the run went no further
    assert "newton      1:" in str(info.value)
