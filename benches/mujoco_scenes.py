"""The stepper benchmark's scenes built in MuJoCo (the peer), with the figures they produce.

Each function builds one scene of issue 4 with the seed's data, runs it with
``mujoco.rollout`` (the stepping loop in C++, no Python per step), and returns the steps per
second and the scene's figures, so ``benches/peer_step.py`` can put them beside coulomb's.
MuJoCo's contacts are soft (solref/solimp) and its friction cone is pyramidal by default; its
defaults are used unless a scene says otherwise, as a user would.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

G0 = 9.81


@dataclass
class PeerRun:
    """One scene run by the peer."""

    scene: str
    h: float
    steps: int
    seconds: float
    figures: dict[str, float] = field(default_factory=dict)

    @property
    def steps_per_second(self) -> float:
        return self.steps / self.seconds if self.seconds > 0 else math.inf


#: timed runs per scene, the best kept (benches/peer_step.py --repeats sets it).
REPEATS = 3


def initial_state(xml: str, qvel0: dict[int, float] | None, h: float):
    """MuJoCo's model of ``xml`` at step h, its data, and the full-physics state to roll out
    from (the velocities ``qvel0`` set)."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(xml)
    model.opt.timestep = h
    data = mujoco.MjData(model)
    if qvel0:
        for k, v in qvel0.items():
            data.qvel[k] = v
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state0 = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state0, spec)
    return model, data, state0


def _rollout(xml: str, qvel0: dict[int, float] | None, t_end: float, h: float,
             repeats: int | None = None):
    from mujoco import rollout

    model, data, state0 = initial_state(xml, qvel0, h)
    nstep = round(t_end / h)
    best = math.inf
    states = None
    for _ in range(REPEATS if repeats is None else repeats):
        start = time.perf_counter()
        states, _ = rollout.rollout(model, data, state0[None, :], nstep=nstep)
        best = min(best, time.perf_counter() - start)
    # full-physics state: [time, qpos, qvel, act, ...]
    nq, nv = model.nq, model.nv
    qpos = states[0, :, 1 : 1 + nq]
    qvel = states[0, :, 1 + nq : 1 + nq + nv]
    times = h * np.arange(1, nstep + 1)
    return times, qpos, qvel, nstep, best


def ramp(h: float = 1e-3, t_end: float = 10.0, mu: float = 0.4, theta_deg: float = 20.0) -> PeerRun:
    """A 1 kg block sent down a 20 deg ramp at 1 m/s with mu = 0.4 (gravity tilted instead of
    the plane). Figures: where it stops, and how far it creeps from t = 5 s to t_end."""
    th = math.radians(theta_deg)
    xml = f"""
<mujoco>
  <option gravity="{G0 * math.sin(th)} 0 {-G0 * math.cos(th)}"/>
  <worldbody>
    <geom type="plane" size="50 5 0.1" friction="{mu} 0.005 0.0001"/>
    <body pos="0 0 0.05">
      <freejoint/>
      <geom type="box" size="0.05 0.05 0.05" mass="1" friction="{mu} 0.005 0.0001"/>
    </body>
  </worldbody>
</mujoco>"""
    t, qpos, qvel, n, sec = _rollout(xml, {0: 1.0}, t_end, h)
    x = qpos[:, 0] - 0.0
    i5 = int(np.searchsorted(t, 5.0))
    return PeerRun(
        "ramp",
        h,
        n,
        sec,
        {
            "distance at 3.011 s (m)": float(np.interp(3.011, t, x)),
            f"creep 5 s..{t_end:g} s (m)": float(x[-1] - x[i5]),
            "speed at t_end (m/s)": float(qvel[-1, 0]),
        },
    )


def floor_impact_xml(radius: float = 0.1) -> str:
    """MuJoCo's floor impact: a 0.5 kg sphere of ``radius`` 1 cm above a plane, no gravity
    (the impact speed is set as its initial velocity)."""
    return f"""
<mujoco>
  <option gravity="0 0 0"/>
  <worldbody>
    <geom type="plane" size="5 5 0.1"/>
    <body pos="0 0 {radius + 0.01}">
      <freejoint/>
      <geom type="sphere" size="{radius}" mass="0.5"/>
    </body>
  </worldbody>
</mujoco>"""


def floor_impact(
    h: float = 1e-3, v_impact: float = 3.0, radius: float = 0.1, t_end: float = 0.2
) -> PeerRun:
    """A 0.5 kg sphere hits the floor at 3 m/s (e = 0.6 asked; MuJoCo has no coefficient, so
    its default soft contact decides). Figure: rebound speed / impact speed."""
    xml = floor_impact_xml(radius)
    _t, _qpos, qvel, n, sec = _rollout(xml, {2: -v_impact}, t_end, h)
    return PeerRun(
        "floor impact",
        h,
        n,
        sec,
        {"rebound ratio (e asked 0.6)": float(qvel[-1, 2] / v_impact)},
    )


def resting_box(h: float = 1e-3, t_end: float = 10.0) -> PeerRun:
    """A box resting on the floor for 10 s. Figures: how far it moved and its penetration."""
    xml = """
<mujoco>
  <worldbody>
    <geom type="plane" size="5 5 0.1"/>
    <body pos="0 0 0.05">
      <freejoint/>
      <geom type="box" size="0.1 0.1 0.05" mass="1"/>
    </body>
  </worldbody>
</mujoco>"""
    _t, qpos, _qvel, n, sec = _rollout(xml, None, t_end, h)
    drift = float(np.max(np.abs(qpos[:, :2] - qpos[0, :2])))
    return PeerRun(
        "resting box",
        h,
        n,
        sec,
        {"horizontal drift (m)": drift, "penetration (m)": float(0.05 - qpos[-1, 2])},
    )


def sphere_pile(count: int, h: float = 1e-3, t_end: float = 1.0, radius: float = 0.05,
                lift: float = 0.0, repeats: int | None = None) -> PeerRun:
    """`count` spheres dropped on a grid into a box (floor and four walls), mu = 0.5; the grid
    raised by ``lift`` metres (high enough, nothing touches within the run: free fall)."""
    side = math.ceil(count ** (1 / 3))
    spacing = 2.2 * radius
    half = side * spacing / 2 + radius
    bodies = []
    for k in range(count):
        i, j, l = k % side, (k // side) % side, k // (side * side)
        x = -half + radius + spacing * (i + 0.5)
        y = -half + radius + spacing * (j + 0.5)
        z = lift + radius + 0.01 + spacing * l
        bodies.append(
            f'<body pos="{x:.4f} {y:.4f} {z:.4f}"><freejoint/>'
            f'<geom type="sphere" size="{radius}" mass="0.1" friction="0.5 0.005 0.0001"/></body>'
        )
    walls = "".join(
        f'<geom type="plane" size="{half} 1 0.1" pos="{px} {py} 1" zaxis="{nx} {ny} 0"/>'
        for px, py, nx, ny in (
            (-half, 0, 1, 0),
            (half, 0, -1, 0),
            (0, -half, 0, 1),
            (0, half, 0, -1),
        )
    )
    # MuJoCo's default arena cannot hold 10^4 free bodies' contacts
    size = '<size memory="4G"/>' if count > 2000 else ""
    xml = f"""
<mujoco>
  {size}
  <worldbody>
    <geom type="plane" size="{half} {half} 0.1" friction="0.5 0.005 0.0001"/>
    {walls}
    {"".join(bodies)}
  </worldbody>
</mujoco>"""
    _t, _qpos, _qvel, n, sec = _rollout(xml, None, t_end, h, repeats)
    return PeerRun(f"pile of {count} spheres", h, n, sec, {})


def box_tower(count: int = 10, h: float = 1e-3, t_end: float = 10.0, half: float = 0.1,
              mu: float = 0.5) -> PeerRun:
    """`count` cubes of side `2 half` (1 kg, mu 0.5) stacked exactly on the floor, standing
    for `t_end`. Figures: the largest horizontal drift of any box, and how far the top box
    sank (its soft contacts' penetration summed down the tower)."""
    bodies = "".join(
        f'<body pos="0 0 {half * (2 * k + 1):.6f}"><freejoint/>'
        f'<geom type="box" size="{half} {half} {half}" mass="1" friction="{mu} 0.005 0.0001"/>'
        f"</body>"
        for k in range(count)
    )
    xml = f"""
<mujoco>
  <worldbody>
    <geom type="plane" size="5 5 0.1" friction="{mu} 0.005 0.0001"/>
    {bodies}
  </worldbody>
</mujoco>"""
    _t, qpos, _qvel, n, sec = _rollout(xml, None, t_end, h)
    pos = qpos.reshape(len(qpos), count, 7)[:, :, :3]
    drift = float(np.max(np.abs(pos[:, :, :2])))
    sink = float(half * (2 * count - 1) - pos[-1, -1, 2])
    return PeerRun(
        f"tower of {count} boxes",
        h,
        n,
        sec,
        {"largest drift (m)": drift, "top box sank (m)": sink},
    )


def box_pile_layout(count: int, half: float = 0.05):
    """The box pile's grid (as benches/peer_step.py builds it): `side` boxes per row, the
    walls' half width, and each box's centre, each layer turned by 10 deg about z."""
    side = math.ceil(count ** (1 / 3))
    spacing = 2.6 * half
    wall = side * spacing / 2 + 2 * half
    centres = []
    for k in range(count):
        i, j, l = k % side, (k // side) % side, k // (side * side)
        centres.append((
            -side * spacing / 2 + spacing * (i + 0.5),
            -side * spacing / 2 + spacing * (j + 0.5),
            1.5 * half + spacing * l,
        ))
    return side, wall, centres


def box_pile(count: int, h: float = 1e-3, t_end: float = 1.0, half: float = 0.05,
             mu: float = 0.5, repeats: int | None = None) -> PeerRun:
    """`count` cubes of side `2 half` (0.1 kg, mu 0.5) dropped on a grid into a box (floor and
    four walls). Figures: the deepest penetration at the end (floor), the largest speed."""
    _side, wall, centres = box_pile_layout(count, half)
    turn = math.radians(10.0)
    bodies = []
    for k, (x, y, z) in enumerate(centres):
        a = turn * (k % 3)
        bodies.append(
            f'<body pos="{x:.6f} {y:.6f} {z:.6f}" euler="0 0 {a:.6f}"><freejoint/>'
            f'<geom type="box" size="{half} {half} {half}" mass="0.1" '
            f'friction="{mu} 0.005 0.0001"/></body>'
        )
    walls = "".join(
        f'<geom type="plane" size="{wall} 1 0.1" pos="{px} {py} 1" zaxis="{nx} {ny} 0" '
        f'friction="{mu} 0.005 0.0001"/>'
        for px, py, nx, ny in ((-wall, 0, 1, 0), (wall, 0, -1, 0), (0, -wall, 0, 1),
                               (0, wall, 0, -1))
    )
    xml = f"""
<mujoco>
  <size memory="200M"/>
  <worldbody>
    <geom type="plane" size="{wall} {wall} 0.1" friction="{mu} 0.005 0.0001"/>
    {walls}
    {"".join(bodies)}
  </worldbody>
</mujoco>"""
    _t, qpos, qvel, n, sec = _rollout(xml, None, t_end, h, repeats)
    pos = qpos.reshape(len(qpos), count, 7)
    lowest = float(np.min(_lowest_corner(pos[-1], half)))
    speed = float(np.max(np.linalg.norm(qvel[-1].reshape(count, 6)[:, :3], axis=1)))
    return PeerRun(
        f"pile of {count} boxes",
        h,
        n,
        sec,
        {
            "floor penetration at the end (m)": max(0.0, -lowest),
            "largest speed at the end (m/s)": speed,
        },
    )


def _lowest_corner(q: np.ndarray, half: float) -> np.ndarray:
    """each box's lowest corner height, from its pose rows (x, y, z, qw, qx, qy, qz)."""
    w, x, y, z = q[:, 3], q[:, 4], q[:, 5], q[:, 6]
    # the third row of the rotation matrix: the body axes' z components
    r = np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=1)
    return q[:, 2] - half * np.sum(np.abs(r), axis=1)


def chain(links: int = 20, h: float = 1e-3, t_end: float = 1.0, length: float = 0.05,
          radius: float = 0.005) -> PeerRun:
    """`links` capsules of length `length` (10 g each) hinged end to end about y, the first
    hinged to the world at the origin, released horizontal along +x (MuJoCo's joint chain:
    each link a child body with a hinge). Figures: the energy change and the tip's height at
    the end."""
    m = 0.01

    def link(k: int) -> str:
        pos = "0 0 0" if k == 0 else f"{length} 0 0"
        inner = link(k + 1) if k + 1 < links else ""
        return (
            f'<body pos="{pos}"><joint type="hinge" axis="0 1 0"/>'
            f'<geom type="capsule" fromto="0 0 0 {length} 0 0" size="{radius}" mass="{m}" '
            f'contype="0" conaffinity="0"/>{inner}</body>'
        )

    xml = f"""
<mujoco>
  <option gravity="0 0 {-G0}"/>
  <worldbody>{link(0)}</worldbody>
</mujoco>"""
    import mujoco

    model = mujoco.MjModel.from_xml_string(xml)
    _t, qpos, qvel, n, sec = _rollout(xml, None, t_end, h)
    data = mujoco.MjData(model)

    def energy(qp: np.ndarray, qv: np.ndarray) -> float:
        data.qpos[:] = qp
        data.qvel[:] = qv
        mujoco.mj_forward(model, data)
        mujoco.mj_energyPos(model, data)
        mujoco.mj_energyVel(model, data)
        return float(data.energy[0] + data.energy[1])

    model.opt.enableflags |= mujoco.mjtEnableBit.mjENBL_ENERGY
    e0 = energy(np.zeros(model.nq), np.zeros(model.nv))
    e1 = energy(qpos[-1], qvel[-1])
    data.qpos[:] = qpos[-1]
    mujoco.mj_kinematics(model, data)
    tip = data.xpos[-1] + data.xmat[-1].reshape(3, 3) @ np.array([length, 0.0, 0.0])
    return PeerRun(
        f"chain of {links} links",
        h,
        n,
        sec,
        {"energy change (J)": e1 - e0, "tip height at the end (m)": float(tip[2])},
    )


if __name__ == "__main__":
    for run in (ramp(), floor_impact(), resting_box(), sphere_pile(100)):
        print(f"{run.scene:24s} h={run.h:g}  {run.steps_per_second:10.0f} steps/s  {run.figures}")
