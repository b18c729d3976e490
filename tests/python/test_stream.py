"""``Scene.stream`` writes the trajectory of ``Scene.simulate`` to an HDF5 file chunk by chunk:
the file holds the same arrays bit for bit (the stepper's state carries over between chunks),
the memory of the run does not grow with its length, and a missing h5py or an unwritable path
is refused before any work."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import coulomb
import numpy as np
import pytest
from coulomb._extras import MissingExtraError
from coulomb.errors import InvalidParameterError

h5py = pytest.importorskip("h5py")

ARRAYS = ("t", "q", "v", "kinetic_energy", "potential_energy", "min_gap", "negative_gaps",
          "active", "solver_error", "solver_scaled_error", "iterations", "momentum_residual",
          "min_normal_impulse", "cone_violation", "complementarity", "resumed", "fallback",
          "projection", "contact_step", "contact_id", "contact_impulse", "contact_velocity",
          "contact_approach", "contact_gap", "contact_closed", "load_power")


def landing_box() -> coulomb.Scene:
    """2D: a spinning box landing on a corner, sliding, two coupled contacts (warm starts and
    the impact memory matter)."""
    s = coulomb.Scene(dim=2)
    b = s.add(coulomb.RigidBody2D(mass=1.0, inertia=0.1, position=(0.0, 0.6),
                                  velocity=(1.0, -0.5), angular_velocity=0.3))
    s.contact(s.attach(b, coulomb.Box((0.5, 0.5))), s.add(coulomb.HalfSpace()), mu=0.4, e=0.5)
    return s


def pile() -> coulomb.Scene:
    """3D: spheres dropped onto a floor and onto each other (broad phase, persistence)."""
    s = coulomb.Scene(dim=3)
    floor = s.add(coulomb.HalfSpace((0.0, 0.0, 0.0), (0.0, 0.0, 1.0)))
    for k in range(6):
        b = s.add(coulomb.Particle(mass=1.0 + 0.1 * k,
                                   position=(0.05 * (k % 3), 0.02 * k, 0.5 + 1.05 * k)))
        s.contact(s.attach(b, coulomb.Sphere(radius=0.5)), floor, mu=0.5, e=0.3)
    s.contact_spheres(mu=0.5, e=0.3)
    return s


def assert_same(a: coulomb.Trajectory, b: coulomb.Trajectory) -> None:
    for name in ARRAYS:
        x, y = getattr(a, name), getattr(b, name)
        assert x.shape == y.shape, name
        assert x.dtype == y.dtype or x.dtype.kind == y.dtype.kind, name
        np.testing.assert_array_equal(x, y, err_msg=name)
    assert list(a.solver_status) == list(b.solver_status)
    assert (a.status, a.success, a.stopped) == (b.status, b.success, b.stopped)
    assert (a.h, a.solver, a.tol, a.gap_tolerance, a.record_every) == (
        b.h, b.solver, b.tol, b.gap_tolerance, b.record_every)


@pytest.mark.parametrize("make", [landing_box, pile])
@pytest.mark.parametrize(("every", "chunk"), [(1, 1), (1, 7), (1, 100_000), (3, 5), (50, 2)])
def test_the_streamed_file_is_the_one_shot_trajectory_bit_for_bit(tmp_path, make, every,
                                                                  chunk):
    kw = {"record_every": every, "max_iter": 30, "fallback": False}
    whole = make().simulate(0.8, 1e-3, **kw)
    assert whole.active.max() >= 2  # contacts were active (and warm-started across chunks)
    path = tmp_path / "run.h5"
    out = make().stream(path, 0.8, 1e-3, chunk=chunk, **kw)
    assert out.path == path
    assert out.states == len(whole.t) and out.steps == len(whole.active)
    assert out.chunks == -(-(len(whole.t) - 1) // chunk)
    assert (out.status, out.success, out.stopped) == (whole.status, whole.success, None)
    back = coulomb.Trajectory.load(path, scene=make())
    assert_same(back, whole)
    assert_same(out.load(scene=make()), whole)


def pushed_box() -> coulomb.Scene:
    """2D: a box pushed along the floor by a constant force (a load besides gravity)."""
    s = coulomb.Scene(dim=2)
    b = s.add(coulomb.RigidBody2D(mass=2.0, inertia=0.2, position=(0.0, 0.55),
                                  velocity=(0.3, 0.0), force=(3.0, -1.0)))
    s.contact(s.attach(b, coulomb.Box((0.5, 0.5))), s.add(coulomb.HalfSpace()), mu=0.1, e=0.0)
    return s


def test_the_load_power_is_f_dot_v_with_or_without_the_scene(tmp_path):
    scene = pushed_box()
    path = tmp_path / "run.h5"
    scene.stream(path, 0.3, 1e-3, chunk=40)
    f = np.array([3.0, -1.0 - 2.0 * 9.81, 0.0])  # F + m g on (x, y, theta)
    for back in (coulomb.Trajectory.load(path), coulomb.Trajectory.load(path, scene=scene)):
        np.testing.assert_allclose(back.load_power, back.v @ f, rtol=1e-14, atol=1e-14)
        assert np.ptp(back.load_power) > 0.5  # the force did work that changed over the run
    # a file of the first version has no load power: it is formed from the scene
    with h5py.File(path, "r+") as h:
        del h["load_power"]
    old = coulomb.Trajectory.load(path, scene=scene)
    np.testing.assert_allclose(old.load_power, old.v @ f, rtol=1e-14, atol=1e-14)
    np.testing.assert_array_equal(coulomb.Trajectory.load(path).load_power, 0.0)


def test_a_failed_step_in_the_stream_is_kept_and_counted(tmp_path):
    kw = {"max_iter": 1, "fallback": False, "tol": 1e-14, "record_every": 50}
    whole = landing_box().simulate(1.0, 1e-3, **kw)
    out = landing_box().stream(tmp_path / "f.h5", 1.0, 1e-3, chunk=3, **kw)
    failed = sum(s not in ("solved", "no_contact") for s in whole.solver_status)
    assert failed > 0
    assert out.failed_steps == failed and not out.success
    assert out.status == whole.status == coulomb.Status.SOLVER_FAILURES


def test_a_file_with_a_step_status_code_out_of_range_is_refused(tmp_path):
    path = tmp_path / "bad.h5"
    landing_box().stream(path, 0.05, 1e-3, chunk=10)
    with h5py.File(path, "r+") as f:
        codes = f["status"][:].astype(np.uint8)
        del f["status"]
        codes[3] = 7
        f.create_dataset("status", data=codes)
    with pytest.raises(coulomb.errors.ProblemFormatError, match="status codes"):
        coulomb.Trajectory.load(path)


#: a child process that runs one call on the 3D pile and prints its peak resident memory (KiB).
PEAK = """
import resource, sys
sys.path.insert(0, {here!r})
from test_stream import pile
scene = pile()
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
{call}
print(before, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
"""


def peak_growth(call: str) -> int:
    """how much a fresh process's peak resident memory grew (bytes) during `call`."""
    code = PEAK.format(here=str(Path(__file__).parent), call=call)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split()
    return (int(out[-1]) - int(out[-2])) * 1024


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="ru_maxrss in KiB on Linux")
def test_memory_does_not_grow_with_the_length_of_the_run(tmp_path):
    stream = "scene.stream({path!r}, {t}, 1e-3, chunk=256)"
    short = peak_growth(stream.format(path=str(tmp_path / "a.h5"), t=4.0))
    long = peak_growth(stream.format(path=str(tmp_path / "b.h5"), t=32.0))
    with h5py.File(tmp_path / "b.h5") as f:
        assert f["t"].shape[0] == 32001
        written = sum(f[k].nbytes for k in f)
    # 8x the steps written (28 MB), the streamed run's peak the same within a few chunks'
    # worth (measured: 4.6 MB and 5.1 MB; the one-shot simulate of 32 s grows by 48 MB)
    assert long < short + written / 20, (short, long, written)


def test_without_h5py_stream_names_the_extra_before_any_work(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "h5py", None)
    called = []
    monkeypatch.setattr(coulomb._core, "step_stream", lambda *a, **k: called.append(1))
    path = tmp_path / "run.h5"
    with pytest.raises(MissingExtraError, match=r"coulomb\[hdf5\]") as info:
        landing_box().stream(path, 0.1, 1e-3)
    assert info.value.extra == "hdf5"
    with pytest.raises(MissingExtraError, match=r"coulomb\[hdf5\]"):
        coulomb.Trajectory.load(path)
    assert not called and not path.exists()


@pytest.mark.parametrize("bad", ["missing_dir/run.h5", "."])
def test_an_unwritable_path_is_refused_before_any_step(tmp_path, monkeypatch, bad):
    called = []
    monkeypatch.setattr(coulomb._core, "step_stream", lambda *a, **k: called.append(1))
    with pytest.raises(InvalidParameterError, match="trajectory file"):
        landing_box().stream(tmp_path / bad, 0.1, 1e-3)
    assert not called


@pytest.mark.parametrize("chunk", [0, -1, 2.5])
def test_a_bad_chunk_is_refused(tmp_path, chunk):
    with pytest.raises(InvalidParameterError, match="chunk"):
        landing_box().stream(tmp_path / "run.h5", 0.1, 1e-3, chunk=chunk)


def test_a_file_that_is_not_a_trajectory_is_refused(tmp_path):
    path = tmp_path / "other.h5"
    with h5py.File(path, "w") as f:
        f["x"] = np.zeros(3)
    with pytest.raises(coulomb.errors.ProblemFormatError, match="not a coulomb trajectory"):
        coulomb.Trajectory.load(path)


@pytest.mark.skipif(sys.platform == "win32", reason="needs POSIX signals")
def test_ctrl_c_leaves_the_chunks_written_and_the_file_marked_incomplete(tmp_path):
    sys.path.insert(0, str(Path(__file__).parent))
    from test_interrupt import interrupt

    path = tmp_path / "run.h5"
    got = interrupt(f"pile(10).stream({str(path)!r}, 10000.0, 1e-3, record_every=100, "
                    "chunk=16)", delay=1.5)
    assert got["outcome"] == "KeyboardInterrupt", got
    with h5py.File(path) as f:
        assert not f.attrs["complete"]
        rows = f["t"].shape[0]
    assert rows > 1 and (rows - 1) % 16 == 0  # whole chunks only
    back = coulomb.Trajectory.load(path)
    assert back.status == coulomb.Status.STOPPED and not back.success
    assert "interrupted" in back.stopped
    np.testing.assert_array_equal(np.diff(back.t) > 0, True)


# the swallowed KeyboardInterrupt is reported as unraisable: that is the case under test
@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_a_ctrl_c_swallowed_in_a_weakref_callback_still_stops_the_stream():
    # Python runs signal handlers between bytecodes; inside a weakref callback (h5py's
    # objects die in them while a chunk is written) the KeyboardInterrupt is printed and
    # ignored, and the run went on. The stream records Ctrl-C and raises it at the next chunk.
    import os
    import signal
    import weakref

    from coulomb import _stream

    class Thing:
        pass

    def callback(_: object) -> None:
        os.kill(os.getpid(), signal.SIGINT)
        for _k in range(1000):  # bytecodes: the handler runs here, its exception is ignored
            pass

    with _stream.CtrlC() as ctrl_c:
        thing = Thing()
        ref = weakref.ref(thing, callback)
        del thing  # the callback runs now and swallows the KeyboardInterrupt
        assert ref() is None
        assert ctrl_c.seen
        with pytest.raises(KeyboardInterrupt):
            ctrl_c.check()
    # the default handler is back
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
