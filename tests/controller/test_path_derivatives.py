"""The compiled path derivatives give the same floats as the NumPy expressions they
replaced (the plans, and so the streams, stay the same bytes): on random polylines of 2
to 40 points at scales from 1 um to 10 mm, an arc meeting a line, duplicates, a uniform line."""

from __future__ import annotations

import numpy as np
import pytest

from cadcnc.controller import path_derivatives as pd
from cadcnc.controller.machine import Machine
from cadcnc.controller.pieces import DUPLICATE, substeps_for


def _norm_rows(x):
    return np.linalg.norm(x, axis=1)


def _curvature(points):
    n = len(points)
    if n < 3:
        return np.zeros(n)
    a, b = points[1:-1] - points[:-2], points[2:] - points[1:-1]
    c = points[2:] - points[:-2]
    k = 2.0 * _norm_rows(np.cross(a, b)) / (_norm_rows(a) * _norm_rows(b) * _norm_rows(c))
    return np.r_[k[:1], k, k[-1:]]


def _distinct(points):
    h = _norm_rows(np.diff(points, axis=0))
    mask = np.r_[True, h > DUPLICATE]
    pts = points[mask]
    kappa = _curvature(pts)
    h = _norm_rows(np.diff(pts, axis=0))
    k2 = 0.5 * (kappa[:-1] ** 2 + kappa[1:] ** 2)
    return pts, np.r_[0.0, np.cumsum(h * (1.0 + k2 * h * h / 24.0))], kappa, mask


def _lagrange(p, s, at):
    s0, s1, s2 = s
    x = s[at]
    d0, d1, d2 = (s0 - s1) * (s0 - s2), (s1 - s0) * (s1 - s2), (s2 - s0) * (s2 - s1)
    first = (p[0] * (2 * x - s1 - s2) / d0 + p[1] * (2 * x - s0 - s2) / d1
             + p[2] * (2 * x - s0 - s1) / d2)
    return first, 2.0 * (p[0] / d0 + p[1] / d1 + p[2] / d2)


def _end(p, s, end):
    if len(p) < 3:
        d = p[-1] - p[0]
        return d / np.linalg.norm(d), np.zeros(3)
    sl = slice(-3, None) if end else slice(0, 3)
    t, k = _lagrange(p[sl], s[sl] - s[sl][0], 2 if end else 0)
    if len(p) >= 4:
        sl = slice(-4, -1) if end else slice(1, 4)
        k = 2.0 * k - _lagrange(p[sl], s[sl] - s[sl][0], 0)[1]
    return t / np.linalg.norm(t), k


def _cut(p, s):
    n = len(p)
    h = np.diff(s)
    d1 = np.diff(p, axis=0) / h[:, None]
    T = np.empty((n, 3))
    T[1:-1] = (d1[:-1] * h[1:, None] + d1[1:] * h[:-1, None]) / (h[:-1] + h[1:])[:, None]
    T[0], T[-1] = _end(p, s, False)[0], _end(p, s, True)[0]
    T /= _norm_rows(T)[:, None]
    K, D, jump = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3))
    if n >= 3:
        K[1:-1] = 2.0 * np.diff(d1, axis=0) / (h[:-1] + h[1:])[:, None]
        K[0], K[-1] = K[1], K[-2]
        dk = np.abs(np.diff(K, axis=0))
        D[:-1] = dk / h[:, None]
        D[1:] = np.maximum(D[1:], D[:-1])
        nb = np.zeros_like(dk)
        nb[1:] = dk[:-1]
        nb[:-1] = np.maximum(nb[:-1], dk[1:])
        excess = np.maximum(dk - nb, 0.0)
        jump[:-1] = excess
        jump[1:] = np.maximum(jump[1:], excess)
    return T, K, D, jump


def _polylines():
    rng = np.random.default_rng(7)
    out = []
    for _ in range(60):
        n = int(rng.integers(2, 41))
        out.append(np.cumsum(rng.normal(size=(n, 3)) * 10 ** rng.uniform(-3, 1), axis=0))
    arc = np.linspace(0.0, np.pi / 2, 200)   # a quarter arc with a line: a curvature jump
    out.append(np.r_[np.c_[9 * np.sin(arc), np.zeros(200), 9 * (1 - np.cos(arc))],
                     np.c_[np.full(50, 9.0), np.zeros(50), 9 + np.linspace(0.1, 5, 50)]])
    dup = out[0].copy()   # consecutive duplicates
    out.append(np.repeat(np.cumsum(np.ones((12, 3)), axis=0), 2, axis=0))
    out.append(np.r_[dup, dup[-1:]])
    out.append(np.c_[np.linspace(0, 10, 21), np.zeros(21), np.zeros(21)])   # uniform
    return out


@pytest.mark.parametrize("k", range(64))
def test_the_same_floats_as_numpy(k):
    points = _polylines()[k]
    got, want = pd.distinct(points, DUPLICATE), _distinct(points)
    for g, w in zip(got, want):
        assert np.array_equal(g, w)
    pts, s, kappa, _ = want
    if len(pts) < 2:
        return
    for end in (False, True):
        for g, w in zip(pd.end_derivatives(pts, s, end), _end(pts, s, end)):
            assert np.array_equal(g, w)
    got = pd.cut_derivatives(pts, s, _end(pts, s, False)[0], _end(pts, s, True)[0])
    for g, w in zip(got, _cut(pts, s)):
        assert np.array_equal(g, w)
    caps = np.random.default_rng(k).uniform(1.0, 100.0, len(pts))
    machine = Machine(0.001, (100.0, 80.0, 50.0), (1e3,) * 3, (1e4,) * 3)
    tangent = np.gradient(pts, s, axis=0)
    tangent /= _norm_rows(tangent)[:, None]
    with np.errstate(divide="ignore"):
        axes = np.min(np.asarray(machine.max_velocity) / np.abs(tangent), axis=1)
    need = float(np.max(np.minimum(axes, 40.0) / caps))
    assert pd.substep_need(pts, s, caps, 40.0, np.asarray(machine.max_velocity)) == need
    want = int(min(max(np.ceil(need - 1e-9), 1), 8))
    assert substeps_for(pts, s, caps, 40.0, machine) == want
