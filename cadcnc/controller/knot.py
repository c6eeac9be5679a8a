"""One knot of the phase plane (compiled): its acceleration constraints, the tangential
accelerations they allow from a speed, and the largest speed at its start from which its
end can still be reached at a given speed (closed form; see :func:`largest`).

At both ends of a knot of length h > 0, per axis i, for every T_i in [Tc - Tr, Tc + Tr]
and K_i in [Kc - Kr, Kc + Kr] (see :mod:`.topp`): |T_i u + K_i w| <= A_i and the
Coriolis term 3 Kmax_i v |u| <= C_i. Lengths mm, speeds mm/s, w = v² mm²/s², u mm/s².
"""

from __future__ import annotations

import math

from numba import njit

ROWS = 24   # acceleration constraints per knot: 2 ends x 3 axes x 4 corners of the box
BISECTIONS = 40   # the fallback: the top of the feasible speeds to 2^-40 of its bracket
SHRINKS = 4       # the closed form's top lowered by 1e-15 .. 1e-12 if round-off fails it
ROOT_STEPS = 60   # Newton steps for a Coriolis root at most (converges in a few)
DOWN_STEPS = 64   # then steps of growing ulps onto it from the infeasible side
EPS = 2.0 ** -52


@njit(cache=True, error_model="numpy")
def coefficients(k: int, h: float, Tc, Tr, Kc, Kr, Kmax, A, C, cu, cw, rhs) -> tuple:
    """Knot k's acceleration constraints cu u + cw w <= rhs (at most ROWS, into the
    buffers' first rows) for the speed w at its start, and its Coriolis bound: (c, m),
    |u| <= c / sqrt(w) and the m rows written. A row the same as one before it (no box
    on T: both of its corners; the knot's end where nothing changes along it and there is
    no curvature: its start's) and a row with no term (an axis the knot does not move)
    are left out: every bound is a minimum or maximum over the rows, and a row left out
    is one already there or one that bounds nothing, so the bounds are the same floats."""
    n = 0
    for e in range(2):
        j = k + e
        reach = 2.0 * h if e == 1 else 0.0
        for i in range(3):
            if e == 1 and (Tc[j, i] == Tc[k, i] and Tr[j, i] == Tr[k, i]
                           and Kc[k, i] == 0.0 and Kr[k, i] == 0.0
                           and Kc[j, i] == 0.0 and Kr[j, i] == 0.0):
                continue   # the end's rows are the start's
            corners = 1 if Tr[j, i] == 0.0 else 2
            for s1 in (-1.0, 1.0):
                kw = s1 * Kc[j, i] + Kr[j, i]
                for q in range(corners):
                    x = s1 * Tc[j, i] + (1.0 if q else -1.0) * Tr[j, i] + kw * reach
                    if x == 0.0 and kw == 0.0 and A[i] > 0.0:   # bounds nothing
                        continue
                    cu[n] = x
                    cw[n] = kw
                    rhs[n] = A[i]
                    n += 1
    c = math.inf
    for i in range(3):
        km = max(Kmax[k, i], Kmax[k + 1, i])
        if km > 0.0:
            c = min(c, C[i] / (3.0 * km))
    return c, n


@njit(cache=True, error_model="numpy")
def bounds(w: float, h: float, cu, cw, rhs, coriolis: float) -> tuple:
    """(lo, hi): the tangential accelerations feasible from speed w on a knot of length
    h > 0 with the constraints of :func:`coefficients` (lo > hi: none)."""
    lo, hi = -w / (2.0 * h), math.inf
    for j in range(len(cu)):
        r = rhs[j] - cw[j] * w
        if cu[j] > 0.0:
            hi = min(hi, r / cu[j])
        elif cu[j] < 0.0:
            lo = max(lo, r / cu[j])
        elif r < 0.0:
            return 1.0, -1.0
    if w > 0.0 and coriolis < math.inf:
        c = coriolis / math.sqrt(w)
        lo, hi = max(lo, -c), min(hi, c)
    return lo, hi


@njit(cache=True, error_model="numpy")
def feasible(w, h, w_next, cu, cw, rhs, coriolis) -> bool:
    """Whether the knot's end can be reached at a squared speed <= w_next from w."""
    lo, hi = bounds(w, h, cu, cw, rhs, coriolis)
    return lo <= hi and w + 2.0 * h * lo <= w_next + 1e-12 * w   # (w - w: round-off)


@njit(cache=True, error_model="numpy")
def _cubic_root(q: float, p: float, c: float, x: float) -> float:
    """The first x' > 0 where q x'³ + p x' + c (c > 0) reaches 0, if below ``x`` (else
    ``x``), on the side where the cubic is still >= 0 and within a few ulps of the root.

    Newton's method from the end of the bracket from which it converges monotonically
    (the cubic is concave on x > 0 for q <= 0: from the right end; convex up to its
    minimum for q > 0: from the left), a bisection step where one would leave the
    bracket; from the right, then down onto the root by growing ulps."""
    if q * x ** 3 + p * x + c >= 0.0 and not (q > 0.0 and p < 0.0):
        return x
    hi = x
    if q > 0.0 and p < 0.0:   # falls to its minimum, then rises
        hi = min(x, math.sqrt(-p / (3.0 * q)))
        if q * hi ** 3 + p * hi + c >= 0.0:
            return x
    lo = 0.0   # the cubic is > 0 at lo, < 0 at hi
    z = lo if q > 0.0 else hi
    for _ in range(ROOT_STEPS):
        f = q * z ** 3 + p * z + c
        if f >= 0.0:
            lo = max(lo, z)
        else:
            hi = min(hi, z)
        d = 3.0 * q * z * z + p
        nxt = z - f / d if d != 0.0 else 0.5 * (lo + hi)
        if nxt == z:   # converged: the step is below z's last bit
            break
        if not lo < nxt < hi:
            nxt = 0.5 * (lo + hi)
        if hi - lo <= 4.0 * EPS * hi:
            break
        z = nxt
    if q * z ** 3 + p * z + c >= 0.0:
        lo = max(lo, z)
    else:
        hi = min(hi, z)
    if q > 0.0:   # the iterates came from the feasible side: lo is on the root
        return lo
    down, gap = hi, EPS * hi
    for _ in range(DOWN_STEPS):
        down -= gap
        if down <= lo:
            break
        if q * down ** 3 + p * down + c >= 0.0:
            return down
        gap *= 2.0
    return lo


@njit(cache=True, error_model="numpy")
def _crossing(w: float, lp, lq, nl: int, up, uq, nu: int) -> float:
    """The largest w' <= w where max_i (lp + lq w') <= min_j (up + uq w') (the first
    ``nl`` and ``nu`` entries), the crossing of a (lower, upper) pair: the gap is concave
    in w', so from w each step goes to the crossing of the pair binding there, which is
    never below the answer (a pair whose gap closes as w' falls: w itself is returned
    and the caller's check decides)."""
    for _ in range(nl + nu + 2):
        lo, hi = -math.inf, math.inf   # (no branches: most knots stop here)
        for k in range(nl):
            lo = max(lo, lp[k] + lq[k] * w)
        for k in range(nu):
            hi = min(hi, up[k] + uq[k] * w)
        if lo <= hi:
            return w
        i, j = 0, 0   # the first binding pair, as a scan would find it
        while i < nl - 1 and lp[i] + lq[i] * w != lo:
            i += 1
        while j < nu - 1 and up[j] + uq[j] * w != hi:
            j += 1
        d = lq[i] - uq[j]
        if d <= 0.0:
            return w
        nxt = (up[j] - lp[i]) / d
        if not nxt < w:
            return w
        w = nxt
    return w


@njit(cache=True, error_model="numpy")
def largest(top: float, h: float, w_next: float, cu, cw, rhs, coriolis: float,
            buf, a_max: float) -> float:
    """The largest w in [0, top] from which the knot ends at <= w_next, in closed form:
    every bound on u is affine in w (u >= lp + lq w, u <= up + uq w; buffers of ROWS + 1)
    or the Coriolis ±coriolis / sqrt(w); each pair (lower, upper) caps w linearly, or, with
    the Coriolis term, at the first root of a cubic in sqrt(w). Checked with
    :func:`feasible` (lowered by round-off amounts where it fails; then the bisection of
    the feasible interval, whose bracket scales with ``a_max``, the largest acceleration
    limit of any axis)."""
    lp, lq, up, uq = buf[0], buf[1], buf[2], buf[3]
    nl, nu = 1, 1
    lp[0], lq[0] = 0.0, -0.5 / h            # w_next >= 0
    up[0], uq[0] = 0.5 * w_next / h, -0.5 / h   # w_next at most
    best = top
    for j in range(len(cu)):
        if cu[j] > 0.0:
            up[nu], uq[nu] = rhs[j] / cu[j], -cw[j] / cu[j]
            nu += 1
        elif cu[j] < 0.0:
            lp[nl], lq[nl] = rhs[j] / cu[j], -cw[j] / cu[j]
            nl += 1
        elif cw[j] > 0.0:
            best = min(best, rhs[j] / cw[j])
    best = max(_crossing(best, lp, lq, nl, up, uq, nu), 0.0)
    if coriolis < math.inf and best > 0.0:
        x = math.sqrt(best)
        for j in range(nu):   # -c / sqrt(w) <= up + uq w
            x = _cubic_root(uq[j], up[j], coriolis, x)
        for i in range(nl):   # lp + lq w <= c / sqrt(w)
            x = _cubic_root(-lq[i], -lp[i], coriolis, x)
        best = min(best, x * x)
    shrink = 1e-15   # the closed form's round-off: a few ulps below, at most 1e-12
    for _ in range(SHRINKS):
        if feasible(best, h, w_next, cu, cw, rhs, coriolis):
            return best
        best *= 1.0 - shrink
        shrink *= 10.0
    a, b = 0.0, min(top, w_next + 2.0 * h * a_max * 1e3)
    for _ in range(BISECTIONS):
        m = 0.5 * (a + b)
        if feasible(m, h, w_next, cu, cw, rhs, coriolis):
            a = m
        else:
            b = m
    return a
