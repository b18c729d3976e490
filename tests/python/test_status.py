"""coulomb.Status: one str enum for every status the core and the wrappers report."""

from __future__ import annotations

import re
from pathlib import Path

import coulomb
import numpy as np
import pytest
from coulomb import Status

ROOT = Path(__file__).resolve().parents[2]


def _as_str_values(path: Path, type_name: str) -> set[str]:
    """The strings `impl <type_name> { fn as_str ... }` maps the Rust enum's variants to."""
    text = path.read_text()
    block = re.search(
        rf"impl {type_name} \{{.*?fn as_str\(self\) -> &'static str \{{(.*?)\n    \}}",
        text,
        re.S,
    )
    assert block is not None, f"no {type_name}::as_str in {path}"
    values = set(re.findall(rf'{type_name}::\w+ => "(\w+)"', block.group(1)))
    assert values, f"{type_name}::as_str maps no variant"
    return values


def _as_str_map(path: Path, type_name: str) -> dict[str, str]:
    """Variant name -> the string `<type_name>::as_str` gives it."""
    text = path.read_text()
    block = re.search(
        rf"impl {type_name} \{{.*?fn as_str\(self\) -> &'static str \{{(.*?)\n    \}}",
        text,
        re.S,
    )
    assert block is not None, f"no {type_name}::as_str in {path}"
    return dict(re.findall(rf'{type_name}::(\w+) => "(\w+)"', block.group(1)))


def _step_status_codes() -> dict[str, int]:
    """The codes the core gives a trajectory's step statuses (`status_code` in step.rs), by
    the status's string: `None` is a step without an active contact."""
    src = (ROOT / "rust" / "python" / "step.rs").read_text()
    block = re.search(r"fn status_code\(status: Option<ContactStatus>\) -> u8 \{(.*?)\n\}",
                      src, re.S)
    assert block is not None, "no status_code in rust/python/step.rs"
    names = _as_str_map(ROOT / "rust" / "contact" / "mod.rs", "ContactStatus")
    none = re.findall(r"None => (\d+)", block.group(1))
    assert len(none) == 1, "status_code must give a step without contact one code"
    codes = {"no_contact": int(none[0])}
    for variant, c in re.findall(r"Some\(ContactStatus::(\w+)\) => (\d+)", block.group(1)):
        codes[names[variant]] = int(c)
    return codes


def _core_statuses() -> set[str]:
    lcp = _as_str_values(ROOT / "rust" / "lcp" / "mod.rs", "LcpStatus")
    contact = _as_str_values(ROOT / "rust" / "contact" / "mod.rs", "ContactStatus")
    return lcp | contact | set(_step_status_codes())


def test_the_core_s_step_status_codes_are_the_files_codes() -> None:
    from coulomb._stream import STATUS_CODES

    # every ContactStatus has a code, and no step without contact is taken for a solve
    assert _step_status_codes() == STATUS_CODES


def test_every_status_the_core_can_report_is_a_member() -> None:
    values = {s.value for s in Status}
    missing = _core_statuses() - values
    assert not missing, f"statuses the Rust core reports but Status lacks: {sorted(missing)}"


def test_members_equal_format_and_hash_as_their_strings() -> None:
    for s in Status:
        assert isinstance(s, str)
        assert s == s.value and s.value == s
        assert str(s) == s.value and f"{s}" == s.value and f"{s:>20}" == f"{s.value:>20}"
        assert hash(s) == hash(s.value) and {s.value: 1}[s] == 1
        assert Status(s.value) is s
        assert repr(s) == f"Status.{s.name}" and eval(repr(s), {"Status": Status}) is s
    assert Status.SOLVED != "failed" and Status.SOLVED != Status.FAILED
    with pytest.raises(ValueError):
        Status("no_such_status")


def test_lcp_results_carry_members() -> None:
    r = coulomb.lcp.solve([[2.0]], [-6.0])
    assert isinstance(r.status, Status) and r.status == "solved" and r.status is Status.SOLVED
    ray = coulomb.lcp.solve([[-1.0]], [-1.0])
    assert ray.status is Status.RAY_TERMINATION and not ray.success
    none = coulomb.lcp.solve([[-1.0]], [-1.0], method="enumerate")
    assert none.status is Status.NO_SOLUTION and not none.success
    m = np.array([[4.0, 1.0, 0.0], [1.0, 4.0, 1.0], [0.0, 1.0, 4.0]])
    q = np.array([-1.0, -2.0, -3.0])
    capped = coulomb.lcp.solve(m, q, method="pgs", max_iter=1, tol=1e-14)
    assert capped.status is Status.ITERATION_LIMIT and not capped.success


def test_contact_results_carry_members() -> None:
    r = coulomb.contact.solve(np.eye(2) / 2, [-3.0, 1.0], 0.2, dim=2)
    assert isinstance(r.status, Status) and r.status is Status.SOLVED and r.success
    w = np.array([[2.0, 1.0, 0.5], [1.0, 2.0, 0.3], [0.5, 0.3, 2.0]])
    capped = coulomb.contact.solve(w, [-3.0, 1.0, 0.5], 0.3, dim=3, max_iter=1, tol=1e-15)
    assert isinstance(capped.status, Status) and capped.status == capped.status.value
    assert capped.success == (capped.status is Status.SOLVED)


def test_trajectory_statuses_are_members() -> None:
    scene = coulomb.Scene(dim=2, gravity=(0.0, -9.81))
    ball = scene.add(coulomb.Particle(mass=1.0, position=(0.0, 0.5), velocity=(0.0, 0.0)))
    scene.contact(scene.attach(ball, coulomb.Point()), scene.add(coulomb.HalfSpace.ramp(0.0)),
                  mu=0.3)
    tr = scene.simulate(0.5, 1e-2)
    assert Status(tr.status) is Status.COMPLETED and tr.success
    steps = {Status(s) for s in tr.solver_status}
    assert Status.NO_CONTACT in steps and Status.SOLVED in steps
