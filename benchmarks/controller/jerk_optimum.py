"""How fast any jerk-limited plan could be: the time-optimal v/a/j motion of each stretch,
estimated by direct optimization, beside the v/a bound and the stream (issue 35).

The bound (``cadcnc.testing.topp_bound``, TOPP-RA, no jerk) is what the issue's 1.15x
target is measured against. Its stretches are moved here from rest to rest with every
axis's velocity, acceleration and jerk at 100 %: the path p(s) a quintic spline through
the stretch's points in arc length (derivatives T, K, D from it), s(t) = L sigma(t / T)
with sigma a clamped quintic B-spline (rest and zero acceleration at both ends), and the
duration T minimized by SLSQP subject to, at SAMPLES instants and per axis,

    |T_i v| <= V_i,  |T_i s'' + K_i v^2| <= A_i,  |T_i s''' + 3 K_i v s'' + D_i v^3| <= J_i

(and v at most the feed). Any such solution is a motion within the limits (at the
samples), so each figure is an upper estimate of the jerk-limited optimum; more
coefficients (``--coefficients``) bring it down. Shares no code with the planner.

    .venv/bin/python -m benchmarks.controller.jerk_optimum [--programs finish corner pencil]
"""

from __future__ import annotations

import argparse
import math

import numpy as np
from scipy.interpolate import BSpline, make_interp_spline
from scipy.optimize import minimize

from benchmarks.controller.stream_cost import programs
from cadcnc.controller import Machine, stream_program
from cadcnc.ops.stream_steppers import stepper_factory
from cadcnc.testing.topp_bound import MIN_GAP, stretch_time, stretches

FEED = 10_000.0       # mm/min
SAMPLES = 400         # instants at which the limits are imposed
DEGREE = 5
CUSTOM = Machine(0.0005, (100.0, 80.0, 50.0), (1000.0, 800.0, 500.0),
                 (20_000.0, 16_000.0, 10_000.0), "custom INI-like machine, 0.5 ms")


def path_of(group) -> tuple[float, object, float]:
    """(L mm, p(s) a quintic spline (n, 3) in arc length, the stretch's speed cap mm/s)."""
    x = [group[0][0][:1]]
    for p, _ in group:
        for a, b in zip(p[:-1], p[1:]):   # straight moves in 0.5 mm pieces: the spline on them
            n = max(1, math.ceil(np.linalg.norm(b - a) / 0.5)) if len(p) == 2 else 1
            x.append(a + np.linspace(0, 1, n + 1)[1:, None] * (b - a))
    x = np.vstack(x)
    s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(x, axis=0), axis=1))]
    keep = np.r_[True, np.diff(s) >= MIN_GAP]
    x, s = x[keep], s[keep]
    s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(x, axis=0), axis=1))]
    cap = min(c for _, c in group)
    return float(s[-1]), make_interp_spline(s, x, k=min(DEGREE, len(s) - 1)), cap


def optimum(group, machine: Machine, coefficients: int = 40) -> float:
    """Seconds: the shortest rest-to-rest motion of the stretch SLSQP finds (see above)."""
    L, p, cap = path_of(group)
    V, A, J = (np.asarray(x, dtype=float) for x in
               (machine.max_velocity, machine.max_acceleration, machine.max_jerk))
    knots = np.r_[[0.0] * DEGREE, np.linspace(0, 1, coefficients - DEGREE + 1), [1.0] * DEGREE]
    tau = np.linspace(0.0, 1.0, SAMPLES)
    derivs = [p.derivative(k) if k else p for k in range(4)]

    def margins(x: np.ndarray) -> np.ndarray:
        T = x[0]
        sigma = BSpline(knots, np.r_[0.0, 0.0, 0.0, x[1:], 1.0, 1.0, 1.0], DEGREE)
        s = np.clip(L * sigma(tau), 0.0, L)
        sd, sdd, sddd = (L * sigma(tau, k) / T ** k for k in (1, 2, 3))
        t, k, d = (derivs[n](s) for n in (1, 2, 3))
        v = t * sd[:, None]
        a = t * sdd[:, None] + k * (sd ** 2)[:, None]
        j = t * sddd[:, None] + 3.0 * k * (sd * sdd)[:, None] + d * (sd ** 3)[:, None]
        return np.concatenate([(1 - np.abs(v) / V).ravel(), (1 - np.abs(a) / A).ravel(),
                               (1 - np.abs(j) / J).ravel(), 1 - sd / min(cap, 1e9),
                               sigma(tau, 1)])

    x0 = np.r_[1.0, np.linspace(0.0, 1.0, coefficients)[3:-3]]
    while margins(x0).min() < 0.0:   # a slow start within every limit
        x0[0] *= 1.3
    r = minimize(lambda x: x[0], x0, method="SLSQP", options={"maxiter": 500, "ftol": 1e-10},
                 constraints=[{"type": "ineq", "fun": margins}])
    return float(r.x[0]) if r.success and margins(r.x).min() >= -1e-9 else math.inf


def best_optimum(group, machine: Machine, coefficients: int) -> float:
    """The best of three coefficient counts around ``coefficients`` (SLSQP may stop on a
    singular step at one of them); inf if none converged."""
    return min(optimum(group, machine, c) for c in (coefficients - 8, coefficients,
                                                     coefficients + 8))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--programs", nargs="+", default=["finish"],
                    help="corner, pencil, finish (stream_cost.programs())")
    ap.add_argument("--coefficients", type=int, default=40)
    args = ap.parse_args()
    machines = {"default": Machine.default(), "custom": CUSTOM}
    for name, part, program in programs():
        if not name.startswith(tuple(args.programs)):
            continue
        groups = stretches(program, FEED)
        for mname, m in machines.items():
            bound = [stretch_time(g, m) for g in groups]
            best = [best_optimum(g, m, args.coefficients) for g in groups]
            stream = stream_program(program, m, stepper_factory(part), feed=FEED).cycle_time
            print(f"{name.split()[0]:7s} {mname:7s} stretches {len(groups):3d}  bound "
                  f"{sum(bound):.3f} s  jerk-limited optimum <= {sum(best):.3f} s "
                  f"({sum(best) / sum(bound):.3f}x)  stream {stream:.3f} s "
                  f"({stream / sum(bound):.3f}x)", flush=True)
            for k, (b, o) in enumerate(zip(bound, best)):
                print(f"    stretch {k:3d}: bound {b:.4f} s, optimum <= {o:.4f} s", flush=True)


if __name__ == "__main__":
    main()
