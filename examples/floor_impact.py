"""Normal impact on a floor (Satici's chapter 11 worked example): m = 0.5 kg,
v_n^- = -3 m/s, e = 0.6, wherever in the step the impact falls."""

from __future__ import annotations

from coulomb import HalfSpace, Particle, Point, Scene


def impact(h: float, frac: float, speed: float = 3.0) -> tuple[float, float, float]:
    scene = Scene(dim=2, gravity=(0.0, 0.0))
    ball = scene.add(Particle(mass=0.5, position=(0.0, frac * speed * h),
                              velocity=(0.0, -speed)))
    floor = scene.add(HalfSpace((0.0, 0.0), (0.0, 1.0)))
    scene.contact(scene.attach(ball, Point()), floor, e=0.6)
    tr = scene.simulate(4 * h, h)
    tr.check(strict=True)
    return (float(tr.v[-1, 1]), float(tr.contact_impulse[:, 0].sum()),
            float(tr.kinetic_energy[0] - tr.kinetic_energy[-1]))


def main() -> None:
    print("analytic: v_n^+ = 1.8 m/s, P_n = 2.4 N s, loss 1.44 J")
    print(f"{'h':>8} {'impact at':>10} {'v_n^+':>10} {'P_n':>10} {'loss':>10}")
    for h in (1e-2, 1e-3, 1e-4):
        for frac in (0.0, 0.3, 0.9):
            v, p, loss = impact(h, frac)
            print(f"{h:8.0e} {frac:10.1f} {v:10.6f} {p:10.6f} {loss:10.6f}")


if __name__ == "__main__":
    main()
