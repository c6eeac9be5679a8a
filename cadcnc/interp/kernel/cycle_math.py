"""The interpolation cycle's mathematics compiled: cycle.py's functions on flat contact rows.

A contact is CS floats of a float64 array (the state, see layout.py) at offset o: its
parameters, r, r_u, r_w, the unit normal, the forms E F G L M N, the singularity ratio and
the offset R' (mm). Every function mirrors the one of the same name in
``cadcnc/interp/cycle.py`` (the plain-Python reference) operation for operation, with
3-vectors as float tuples; failures are returned as status codes, not raised. No OCCT.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .layout import C_E, C_F, C_G, C_L, C_M, C_N, C_NRM, C_OFF, C_R, C_RU, C_RW, C_SING, C_U, C_W

_jit = numba.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)

PAPER_INVERSE_LIMIT = 1.0 + 1e-9   # cycle.PAPER_INVERSE_LIMIT
MAX_TURN = 0.1                     # cycle.MAX_TURN
SINGULAR_DET = 1e-14               # vec3.SINGULAR_DET


@_jit
def vec(a: np.ndarray, o: int) -> tuple:
    return (a[o], a[o + 1], a[o + 2])


@_jit
def put(a: np.ndarray, o: int, v: tuple) -> None:
    a[o] = v[0]
    a[o + 1] = v[1]
    a[o + 2] = v[2]


@_jit
def sub(a: tuple, b: tuple) -> tuple:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@_jit
def add(a: tuple, b: tuple) -> tuple:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


@_jit
def scale(a: tuple, s: float) -> tuple:
    return (a[0] * s, a[1] * s, a[2] * s)


@_jit
def axpy(s: float, a: tuple, b: tuple) -> tuple:
    return (s * a[0] + b[0], s * a[1] + b[1], s * a[2] + b[2])


@_jit
def dot(a: tuple, b: tuple) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@_jit
def cross(a: tuple, b: tuple) -> tuple:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@_jit
def norm(a: tuple) -> float:
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


@_jit
def set_geometry(S: np.ndarray, o: int, sign: float, u: float, w: float,
                 d: np.ndarray) -> None:
    """Contact.move_to after the evaluation: d (6, 3) holds r, r_u, r_w, r_uu, r_uw, r_ww."""
    r = (d[0, 0], d[0, 1], d[0, 2])
    ru = (d[1, 0], d[1, 1], d[1, 2])
    rw = (d[2, 0], d[2, 1], d[2, 2])
    c = cross(ru, rw)
    cn = norm(c)
    E = dot(ru, ru)
    F = dot(ru, rw)
    G = dot(rw, rw)
    S[o + C_SING] = cn / (E + G + 1e-300)   # 0 / 0 -> 0
    n = scale(c, sign / cn) if cn > 0.0 else (0.0, 0.0, 0.0)
    S[o + C_U] = u
    S[o + C_W] = w
    put(S, o + C_R, r)
    put(S, o + C_RU, ru)
    put(S, o + C_RW, rw)
    put(S, o + C_NRM, n)
    S[o + C_E] = E
    S[o + C_F] = F
    S[o + C_G] = G
    S[o + C_L] = dot((d[3, 0], d[3, 1], d[3, 2]), n)
    S[o + C_M] = dot((d[4, 0], d[4, 1], d[4, 2]), n)
    S[o + C_N] = dot((d[5, 0], d[5, 1], d[5, 2]), n)


@_jit
def tangent_coords(S: np.ndarray, o: int, t: tuple) -> tuple:
    tu = dot(vec(S, o + C_RU), t)
    tw = dot(vec(S, o + C_RW), t)
    E, F, G = S[o + C_E], S[o + C_F], S[o + C_G]
    det = E * G - F * F
    return (G * tu - F * tw) / det, (E * tw - F * tu) / det


@_jit
def curvature(S: np.ndarray, o: int, t: tuple) -> float:
    a, b = tangent_coords(S, o, t)
    return ((S[o + C_L] * a * a + 2.0 * S[o + C_M] * a * b + S[o + C_N] * b * b)
            / (S[o + C_E] * a * a + 2.0 * S[o + C_F] * a * b + S[o + C_G] * b * b))


@_jit
def centre(S: np.ndarray, o: int) -> tuple:
    return axpy(S[o + C_OFF], vec(S, o + C_NRM), vec(S, o + C_R))


@_jit
def principal_curvatures(S: np.ndarray, o: int) -> tuple:
    E, F, G = S[o + C_E], S[o + C_F], S[o + C_G]
    L, M, N = S[o + C_L], S[o + C_M], S[o + C_N]
    det = E * G - F * F
    H = (E * N - 2.0 * F * M + G * L) / (2.0 * det)
    K = (L * N - M * M) / det
    disc = math.sqrt(max(H * H - K, 0.0))
    return H + disc, H - disc


@_jit
def paper_inverse_ratio(S: np.ndarray, o: int, k: float) -> float:
    R = S[o + C_OFF]
    if R == 0.0:
        return 0.0
    k_max, k_min = principal_curvatures(S, o)
    return R * max(abs(k_max - k), abs(k_min - k)) / abs(1.0 - R * k)


@_jit
def sphere_row(S: np.ndarray, o: int, k: float, p_star: tuple, flat: float) -> tuple:
    n = vec(S, o + C_NRM)
    if abs(k) < flat:
        return n, dot(sub(centre(S, o), p_star), n)
    oc = axpy(1.0 / k, n, vec(S, o + C_R))
    v = sub(p_star, oc)
    dist = norm(v)
    d = (1.0 - S[o + C_OFF] * k) / abs(k)
    return scale(v, 1.0 / dist), d - dist


@_jit
def solve3(r0: tuple, r1: tuple, r2: tuple, b: tuple) -> tuple:
    """vec3.solve3: (ok, x)."""
    c12 = cross(r1, r2)
    det = dot(r0, c12)
    scale_ = norm(r0) * norm(r1) * norm(r2)
    if abs(det) <= SINGULAR_DET * scale_:
        return False, (0.0, 0.0, 0.0)
    c20 = cross(r2, r0)
    c01 = cross(r0, r1)
    inv = 1.0 / det
    return True, ((b[0] * c12[0] + b[1] * c20[0] + b[2] * c01[0]) * inv,
                  (b[0] * c12[1] + b[1] * c20[1] + b[2] * c01[1]) * inv,
                  (b[0] * c12[2] + b[1] * c20[2] + b[2] * c01[2]) * inv)


@_jit
def correct(S: np.ndarray, o1: int, o2: int, k1: float, k2: float, p_star: tuple,
            flat: float) -> tuple:
    """(ok, p_e): eq. 4."""
    e1, b1 = sphere_row(S, o1, k1, p_star, flat)
    e2, b2 = sphere_row(S, o2, k2, p_star, flat)
    ok, dp = solve3(e1, e2, cross(e1, e2), (b1, b2, 0.0))
    return ok, add(p_star, dp)


@_jit
def inverse(S: np.ndarray, o: int, k: float, p_e: tuple) -> tuple:
    dr = scale(sub(p_e, centre(S, o)), 1.0 / (1.0 - k * S[o + C_OFF]))
    drr = dot(dr, dr)
    if drr == 0.0:
        return 0.0, 0.0
    ru, rw = vec(S, o + C_RU), vec(S, o + C_RW)
    m = cross(vec(S, o + C_NRM), dr)
    a11, a12 = dot(ru, m), dot(rw, m)
    a21, a22 = dot(ru, dr), dot(rw, dr)
    det = a11 * a22 - a12 * a21
    return (-a12 * drr) / det, (a11 * drr) / det


@_jit
def inverse_exact(S: np.ndarray, o: int, p_e: tuple) -> tuple:
    """(ok, du, dw); not ok where a principal curvature equals 1/R' (CURVATURE)."""
    d = sub(p_e, centre(S, o))
    R = S[o + C_OFF]
    a11 = S[o + C_E] - R * S[o + C_L]
    a12 = S[o + C_F] - R * S[o + C_M]
    a22 = S[o + C_G] - R * S[o + C_N]
    b1, b2 = dot(d, vec(S, o + C_RU)), dot(d, vec(S, o + C_RW))
    det = a11 * a22 - a12 * a12
    if det == 0.0:
        return False, 0.0, 0.0
    return True, (a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det


@_jit
def centre_curvature(S: np.ndarray, o1: int, o2: int, k1: float, k2: float) -> float:
    a = k1 / (1.0 - S[o1 + C_OFF] * k1)
    b = k2 / (1.0 - S[o2 + C_OFF] * k2)
    c = dot(vec(S, o1 + C_NRM), vec(S, o2 + C_NRM))
    return math.sqrt(max(a * a + b * b - 2.0 * c * a * b, 0.0) / max(1.0 - c * c, 1e-300))  # no / 0


@_jit
def model_step(S: np.ndarray, o: int, k: float, t: tuple, carried: tuple, slope: float,
               budget: float) -> float:
    R = S[o + C_OFF]
    E, F, G = S[o + C_E], S[o + C_F], S[o + C_G]
    L, M, N = S[o + C_L], S[o + C_M], S[o + C_N]
    a11, a12, a22 = E - R * L, F - R * M, G - R * N
    det = a11 * a22 - a12 * a12
    if det == 0.0:
        return math.inf
    ru, rw = vec(S, o + C_RU), vec(S, o + C_RW)
    b1, b2 = dot(t, ru), dot(t, rw)
    a0, a1 = (a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det
    b1, b2 = dot(carried, ru), dot(carried, rw)
    e0, e1 = (a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det
    qL, qM, qN = L - k * E, M - k * F, N - k * G
    q2 = abs(qL * a0 * a0 + 2.0 * qM * a0 * a1 + qN * a1 * a1)
    q1 = abs(qL * a0 * e0 + qM * (a0 * e1 + a1 * e0) + qN * a1 * e1)
    q0 = abs(qL * e0 * e0 + 2.0 * qM * e0 * e1 + qN * e1 * e1)
    room = budget - q0
    if q2 == 0.0 and q1 == 0.0:
        f2 = math.inf
    elif room > 0.0:
        f2 = room / (q1 + math.sqrt(q1 * q1 + q2 * room))
    else:
        f2 = 0.5 * math.sqrt(budget / q2) if q2 > 0.0 else math.inf
    if slope <= 0.0:
        return f2
    la = math.sqrt(max(E * a0 * a0 + 2.0 * F * a0 * a1 + G * a1 * a1, 0.0))
    le = math.sqrt(max(E * e0 * e0 + 2.0 * F * e0 * e1 + G * e1 * e1, 0.0))
    reach = (3.0 * budget / slope) ** (1.0 / 3.0)
    f3 = (reach - le) / la if reach > 2.0 * le else 0.5 * reach / la
    return min(f2, f3)


@_jit
def accurate_step(S: np.ndarray, p: tuple, o1: int, o2: int, t: tuple, k1: float,
                  k2: float, f: float, accuracy: float, slope1: float,
                  slope2: float) -> float:
    step = f
    kappa = centre_curvature(S, o1, o2, k1, k2)
    if kappa * f * f > 4.0 * accuracy:
        step = math.sqrt(4.0 * accuracy / kappa)
    if kappa * step > MAX_TURN:
        step = MAX_TURN / kappa
    limit = model_step(S, o1, k1, t, sub(p, centre(S, o1)), slope1, accuracy / 4.0)
    if limit < step:
        step = limit
    limit = model_step(S, o2, k2, t, sub(p, centre(S, o2)), slope2, accuracy / 4.0)
    if limit < step:
        step = limit
    return step
