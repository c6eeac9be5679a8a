"""The jerk-limited optimum of each stretch, refined: ``jerk_optimum``'s estimate made
tighter (issue 35's 1.15x on the custom machine's finish).

For each stretch of the v/a bound (``cadcnc.testing.topp_bound``), moved from rest to
rest with every axis's v, a and j at 100 % as in ``jerk_optimum`` (s(t) = L sigma(t / T),
sigma a clamped quintic B-spline), but: SLSQP with analytic Jacobians (each |x| <= 1 as
two constraints), the limits imposed at 8 instants per knot interval, and the knots
halved level by level (32 -> 59 -> 113 coefficients), each level started from the last
one's motion. Each level's time is made *valid*: the limits are checked on a grid 10x
denser than the instants imposed and T is stretched until none is exceeded (v scales
as 1/T, a as 1/T^2, j as 1/T^3 along the same path). A straight stretch has an exact
optimum (the 1-D jerk-limited S-curve, its limits along the line): printed beside, it
checks the method, which reaches it from above. Every figure is an achievable time, so
an upper estimate of the optimum; shares no code with the planner.

    python -m benchmarks.controller.jerk_optimum_refined [--machine custom|default]
        [--levels 3] [--program finish]

About 7 minutes of CPU on the custom finish (3 levels).
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from scipy.interpolate import BSpline
from scipy.optimize import brentq, minimize

from benchmarks.controller.jerk_optimum import CUSTOM, FEED, path_of
from benchmarks.controller.stream_cost import programs
from cadcnc.controller import Machine
from cadcnc.testing.topp_bound import stretch_time, stretches

DEG = 5


def basis(knots, tau, nu):
    n = len(knots) - DEG - 1
    return BSpline(knots, np.eye(n), DEG)(tau, nu)


class Problem:
    def __init__(self, group, machine: Machine, knots, samples):
        self.V, self.A, self.J = (np.asarray(x, float) for x in (
            machine.max_velocity, machine.max_acceleration, machine.max_jerk))
        self.L, p, cap = path_of(group)
        self.cap = min(cap, 1e9)
        self.d = [p.derivative(k) if k else p for k in range(5)]
        self.knots = knots
        self.n = len(knots) - DEG - 1
        self.tau = samples
        self.B = [basis(knots, samples, nu) for nu in range(4)]
        self.free = slice(3, self.n - 3)
        # axes that actually move (others are checked on the dense grid only)
        s = np.linspace(0, self.L, 2001)
        self.axes = np.nonzero(np.abs(self.d[1](s)).max(0) > 1e-6)[0]

    def coef(self, x):
        c = np.zeros(self.n); c[self.n - 3:] = 1.0; c[self.free] = x[1:]
        return c

    def kin(self, x, B=None, jac=True):
        T = x[0]; L = self.L
        B = self.B if B is None else B
        c = self.coef(x)
        S = [b @ c for b in B]
        s = np.clip(L * S[0], 0.0, L)
        w = 1.0 / T
        sd, sdd, sddd = L * S[1] * w, L * S[2] * w ** 2, L * S[3] * w ** 3
        t, k, d, e = (self.d[m](s) for m in (1, 2, 3, 4))
        v = t * sd[:, None]
        a = t * sdd[:, None] + k * (sd ** 2)[:, None]
        j = t * sddd[:, None] + 3 * k * (sd * sdd)[:, None] + d * (sd ** 3)[:, None]
        out = dict(v=v, a=a, j=j, sd=sd, S1=S[1])
        if not jac:
            return out
        f = self.free
        B0, B1, B2, B3 = (L * b[:, f] for b in B)
        # d/dc: arrays (N, axes, nfree)
        sdN, sddN, sdddN = sd[:, None, None], sdd[:, None, None], sddd[:, None, None]
        tN, kN, dN, eN = t[:, :, None], k[:, :, None], d[:, :, None], e[:, :, None]
        dB0, dB1, dB2, dB3 = B0[:, None, :], (w * B1)[:, None, :], (w ** 2 * B2)[:, None, :], (w ** 3 * B3)[:, None, :]
        dv = kN * sdN * dB0 + tN * dB1
        da = (kN * sddN + dN * sdN ** 2) * dB0 + tN * dB2 + 2 * kN * sdN * dB1
        dj = ((kN * sdddN + 3 * dN * sdN * sddN + eN * sdN ** 3) * dB0 + tN * dB3
              + 3 * kN * (sddN * dB1 + sdN * dB2) + 3 * dN * sdN ** 2 * dB1)
        out.update(dv=dv, da=da, dj=dj, dvT=-v / T, daT=-2 * a / T, djT=-3 * j / T,
                   dsd=w * B1, dsdT=-sd / T, dS1=B[1][:, f] )
        return out

    def cons(self, x):
        q = self.kin(x, jac=False); ax = self.axes
        parts = []
        for key, lim in (("v", self.V), ("a", self.A), ("j", self.J)):
            r = q[key][:, ax] / lim[ax]
            parts += [(1 - r).ravel(), (1 + r).ravel()]
        parts += [1 - q["sd"] / self.cap, q["S1"]]
        return np.concatenate(parts)

    def cons_jac(self, x):
        q = self.kin(x); ax = self.axes; nf = self.n - 6
        rows = []
        for key, lim in (("v", self.V), ("a", self.A), ("j", self.J)):
            dc = q["d" + key][:, ax, :] / lim[ax][None, :, None]
            dT = q["d" + key + "T"][:, ax] / lim[ax][None, :]
            G = np.concatenate([dT[:, :, None], dc], axis=2).reshape(-1, nf + 1)
            rows += [-G, G]
        rows.append(-np.c_[q["dsdT"], q["dsd"]] / self.cap)
        rows.append(np.c_[np.zeros(len(self.tau)), q["dS1"]])
        return np.vstack(rows)

    def excess(self, x, tau):
        """worst relative excess of each limit (all axes) on the instants tau."""
        B = [basis(self.knots, tau, nu) for nu in range(4)]
        q = self.kin(x, B, jac=False)
        return dict(v=(np.abs(q["v"]) / self.V).max() - 1,
                    a=(np.abs(q["a"]) / self.A).max() - 1,
                    j=(np.abs(q["j"]) / self.J).max() - 1, cap=(q["sd"] / self.cap).max() - 1,
                    mono=-q["S1"].min())


def uniform_knots(ncoef):
    return np.r_[[0.0] * DEG, np.linspace(0, 1, ncoef - DEG + 1), [1.0] * DEG]


def halve(knots):
    u = np.unique(knots)
    mid = (u[:-1] + u[1:]) / 2
    return np.r_[[0.0] * DEG, np.sort(np.r_[u, mid]), [1.0] * DEG]


def samples_for(knots, per):
    u = np.unique(knots)
    return np.unique(np.r_[[np.linspace(a, b, per + 1) for a, b in zip(u[:-1], u[1:])]].ravel())


def project(knots_old, c_old, knots_new):
    """coefficients on knots_new of the spline (knots_old, c_old): least squares on dense points."""
    tau = samples_for(knots_new, 12)
    c, *_ = np.linalg.lstsq(basis(knots_new, tau, 0), BSpline(knots_old, c_old, DEG)(tau), rcond=None)
    return c


def valid_time(P, x, per):
    """(T scaled so the motion is within every limit on a grid 10x denser than the samples,
    excess before scaling)."""
    tau = samples_for(P.knots, 10 * per)
    ex = P.excess(x, tau)
    f = max(1.0, 1 + ex["v"], 1 + ex["cap"], math.sqrt(1 + ex["a"]), (1 + ex["j"]) ** (1 / 3))
    if ex["mono"] > 1e-9:
        return math.inf, ex
    return x[0] * f, ex


def solve(P, x0, maxiter=300):
    r = minimize(lambda x: x[0], x0, jac=lambda x: np.r_[1.0, np.zeros(len(x) - 1)], method="SLSQP",
                 bounds=[(0.05, 10.0)] + [(-0.5, 1.5)] * (len(x0) - 1), constraints=[{"type": "ineq", "fun": P.cons, "jac": P.cons_jac}],
                 options={"maxiter": maxiter, "ftol": 1e-12})
    return r


def run_stretch(group, machine: Machine, ncoef0=32, levels=3, per=8, log=print) -> list:
    knots = uniform_knots(ncoef0)
    res: list[dict] = []
    x = kold = cold = None
    for _ in range(levels):
        P = Problem(group, machine, knots, samples_for(knots, per))
        if x is None:
            x0 = np.r_[1.0, np.linspace(0.0, 1.0, P.n)[3:-3]]
            while P.cons(x0).min() < 0.0:
                x0[0] *= 1.3
        else:
            x0 = np.r_[x[0], project(kold, cold, knots)[3:-3]]
            # make the warm start feasible on the new samples by scaling T
            t0, _ = valid_time(P, x0, per)
            x0[0] = t0 * 1.0001
        t0 = time.time()
        r = solve(P, x0)
        tv, ex = valid_time(P, r.x, per)
        # keep the better of the start and the result (both valid after scaling)
        ts, _ = valid_time(P, x0, per)
        if ts < tv:
            tv, ex, xr = ts, valid_time(P, x0, per)[1], x0
        else:
            xr = r.x
        log(f"  coeff {P.n:4d} samples {len(P.tau):5d}: SLSQP T {r.x[0]:.5f} ({r.message}, {r.nit} it) "
            f"valid T {tv:.5f}  dense excess v {ex['v']:+.1e} a {ex['a']:+.1e} j {ex['j']:+.1e} "
            f"cap {ex['cap']:+.1e}  {time.time() - t0:.0f}s")
        res.append(dict(ncoef=P.n, samples=len(P.tau), T_slsqp=float(r.x[0]), T_valid=float(tv),
                        success=bool(r.success), msg=r.message, excess={k: float(v) for k, v in ex.items()}))
        x = xr.copy(); x[0] = tv
        kold, cold = knots, P.coef(x)
        knots = halve(knots)
    return res


def straight_time(L: float, V: float, A: float, J: float) -> float:
    """Seconds: the time-optimal rest-to-rest motion over L mm with speed, acceleration
    and jerk at most V, A, J along the line (the S-curve, closed form)."""
    def t_acc(vp):   # from rest to vp and its length
        return vp / A + A / J if vp >= A * A / J else 2 * math.sqrt(vp / J)

    def d_acc(vp):
        return vp * t_acc(vp) / 2
    vp = V if 2 * d_acc(V) <= L else brentq(lambda v: 2 * d_acc(v) - L, 1e-12, V, xtol=1e-14)
    return t_acc(vp) + L / vp


def exact_if_straight(group, machine: Machine) -> float | None:
    """The closed-form optimum of a straight stretch, None for a curved one."""
    L, p, cap = path_of(group)
    s = np.linspace(0.0, L, 2001)
    if np.abs(p.derivative(2)(s)).max() > 1e-9:
        return None
    t = np.abs(p.derivative(1)(s).mean(axis=0))
    t /= np.linalg.norm(t)
    along = [min(x / ti for x, ti in zip(lim, t) if ti > 1e-12) for lim in (
        machine.max_velocity, machine.max_acceleration, machine.max_jerk)]
    return straight_time(L, min(along[0], cap), along[1], along[2])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--machine", choices=["custom", "default"], default="custom")
    ap.add_argument("--levels", type=int, default=3)
    ap.add_argument("--program", default="finish", help="corner, pencil or finish")
    args = ap.parse_args()
    machine = CUSTOM if args.machine == "custom" else Machine.default()
    for name, _, program in programs():
        if not name.startswith(args.program):
            continue
        bound_sum, best_sum = 0.0, 0.0
        for k, group in enumerate(stretches(program, FEED)):
            bound = stretch_time(group, machine)
            print(f"stretch {k}: bound {bound:.4f} s", flush=True)
            levels = run_stretch(group, machine, levels=args.levels,
                                    log=lambda m: print(m, flush=True))
            best = min(r["T_valid"] for r in levels)
            exact = exact_if_straight(group, machine)
            if exact is not None:
                print(f"  straight: closed form {exact:.5f} s", flush=True)
                best = min(best, exact)
            bound_sum += bound
            best_sum += best
        print(f"{name.split()[0]} {args.machine}: bound {bound_sum:.4f} s, jerk-limited "
              f"optimum <= {best_sum:.4f} s ({best_sum / bound_sum:.4f}x)", flush=True)


if __name__ == "__main__":
    main()
