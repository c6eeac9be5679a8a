"""The gouge gate over a whole program: every cut, and every move written, links included.

:func:`gate_program` runs :func:`~cadcnc.verification.gate.gouge_gate` once per cut
segment: the pair's faces against their offsets and the ball against every face of the
part at the cut's centres, and the ball swept along the moves assigned to that cut, which
are the moves actually written (points dropped, rounded, tool-tip offset taken back) of
the cut itself and of the link before it (the approach for the first cut), plus the final
retract for the last cut. So every move of the program, cuts and links, is bounded
against the whole part exactly once. The program passes only when every cut passes
(fails closed, as the gate does). Lengths mm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..core.errors import require
from ..core.tolerances import Tolerances
from ..program.program import Program
from .gate import GateResult, gouge_gate
from .gate_cache import shared_gates
from .gate_jobs import gate_cuts
from .surface_checks import resolve_part


@dataclass(frozen=True)
class ProgramGate:
    """Per cut (in order) its :class:`GateResult`; ``ok`` when every cut passed."""

    results: list[GateResult] = field(default_factory=list)
    labels: list[str] = field(default_factory=list)
    link_failed: list[bool] = field(default_factory=list)
    """Per cut: a link move assigned to it (before it, or the final retract) fails."""

    @property
    def ok(self) -> bool:
        return bool(self.results) and all(r.ok for r in self.results)

    @property
    def depth_mm(self) -> float:
        """The deepest cut measured over the program, mm (nan when one is unmeasured)."""
        d = [r.depth_mm for r in self.results]
        return math.nan if any(math.isnan(v) for v in d) else max(d, default=math.nan)

    @property
    def failed(self) -> list[tuple[str, GateResult]]:
        return [(lab, r) for lab, r in zip(self.labels, self.results) if not r.ok]

    @property
    def message(self) -> str:
        """Why the program is refused, one clause per failing cut ("" when ok)."""
        return "; ".join(
            f"{lab}{' or the link moves to it' if bad_link else ''}: "
            f"{r.message.replace('; nothing written', '')}"
            for lab, r, bad_link in zip(self.labels, self.results, self.link_failed)
            if not r.ok)


def _joined(parts: list[np.ndarray]) -> np.ndarray | None:
    """The polylines end to end, a repeated joint point dropped; None when empty. Parts
    that lie end to end in one array (a stream's segments) are joined as a read-only view
    of it, not copied."""
    out: list[np.ndarray] = []
    for p in parts:
        p = np.asarray(p, float).reshape(-1, 3)
        if out and len(p) and len(out[-1]) and np.array_equal(out[-1][-1], p[0]):
            p = p[1:]
        if len(p):
            both = _adjacent(out[-1], p) if out else None
            if both is None:
                out.append(p)
            else:
                out[-1] = both
    if not out:
        return None
    return out[0] if len(out) == 1 else np.vstack(out)


def _adjacent(a: np.ndarray, b: np.ndarray) -> np.ndarray | None:
    """``a`` then ``b`` as one read-only view when both are C-contiguous (n, 3) rows of
    the array that owns ``b``'s memory and ``b``'s rows follow ``a``'s, else None."""
    owner = b
    while isinstance(owner.base, np.ndarray):
        owner = owner.base
    if (owner is b or owner.dtype != np.float64 or not owner.flags.c_contiguous
            or owner.size % 3 or not (a.flags.c_contiguous and b.flags.c_contiguous)):
        return None
    start, row = owner.ctypes.data, 3 * owner.itemsize
    if not (start <= a.ctypes.data and a.ctypes.data + a.nbytes == b.ctypes.data
            and b.ctypes.data + b.nbytes <= start + owner.nbytes):
        return None
    first = (a.ctypes.data - start) // row
    view = owner.reshape(-1, 3)[first:first + len(a) + len(b)]
    view.flags.writeable = False
    return view


def _n_moves(polyline) -> int:
    return 0 if polyline is None else max(len(polyline) - 1, 0)


def cut_moves(program, moves: list[np.ndarray]) -> list[tuple[np.ndarray | None, range]]:
    """Per cut, the written moves it answers for: the link(s) before it, its own moves,
    and for the last cut the retract after it, joined into one polyline; with the range
    of move indices that are the cut's own (the others are link moves). ``moves``: per
    segment (see the module doc)."""
    if len(moves) != len(program.segments):
        raise ValueError(f"{len(moves)} move lists for {len(program.segments)} segments")
    groups: list[list[np.ndarray]] = []
    own: list[range] = []
    pending: list[np.ndarray] = []
    for seg, m in zip(program.segments, moves):
        if seg.kind == "cut":
            before = _n_moves(_joined(pending))
            own.append(range(before, before + _n_moves(_joined([m]))))
            groups.append([*pending, m])
            pending = []
        else:
            pending.append(m)
    if groups and pending:
        groups[-1] += pending
    return [(_joined(g), r) for g, r in zip(groups, own)]


def _in_links(result: GateResult, own: range) -> bool:
    """Whether a move outside the cut's own (a link move) fails the gate."""
    sweep = result.sweep
    if sweep is None:
        return False
    return any(not (own.start <= k < own.stop)
               for h in sweep.hits if not h.depth_mm <= sweep.allowance_mm
               for lo, hi in h.moves for k in range(lo, hi + 1))


def last_centre(path) -> tuple:
    """(point (3,), uv (2, 2), faces) of a toolpath's last centre: where the moves of the
    next cut (its link first) start, as :func:`~.whole_part.before_floors` takes it."""
    return path.points[-1], path.uv[-1], path.faces


def cut_label(k: int, seg) -> str:
    where = "".join(f", {w} {v}" for w, v in (("edge", seg.edge), ("stretch", seg.stretch))
                    if v)
    i, j = seg.path.faces
    return f"cut {k} (faces {i} {j}{where})"


def gate_program(program, part=None, tol: Tolerances | None = None, *, moves=None,
                 blend_mm: float = 0.0, progress=None, jobs: int | None = 1,
                 reference: bool = False) -> ProgramGate:
    """The gate of every cut of ``program`` on ``part`` (see the module doc).

    ``moves``: per segment of the program, the (M_k, 3) ball-centre positions written
    (:func:`cadcnc.io.program_gcode.program_written_moves`); default the segments' own
    points (cuts and links as computed). ``tol`` default: the program's job's tolerances.
    ``blend_mm`` and ``progress`` as for :func:`gouge_gate` (with ``jobs`` other than 1,
    progress counts the cuts gated: stage "cuts"). ``jobs``: processes gating cuts at
    once (None: every core); the answer does not depend on it. ``reference``: the
    reference gate (:func:`gouge_gate`).
    """
    require("program", program, Program, "a cadcnc Program")
    tol = program.job.tolerances if tol is None else tol
    if moves is None:
        moves = [s.points for s in program.segments]
    per_cut = cut_moves(program, list(moves))
    labels = [cut_label(k, seg) for k, seg in enumerate(program.cuts, 1)]
    if not program.cuts:
        return ProgramGate([], labels, [])
    part = resolve_part(program.cuts[0].path, part)
    befores = [None] + [last_centre(seg.path) for seg in program.cuts[:-1]]
    with shared_gates(part):  # the cuts share faces, probes and distances
        if jobs == 1:
            results = [gouge_gate(seg.path, part, tol, moves=m, blend_mm=blend_mm,
                                  progress=progress, reference=reference, before=before)
                       for seg, (m, _), before in zip(program.cuts, per_cut, befores)]
        else:
            results = gate_cuts(part, [(seg.path, m, blend_mm, before) for seg, (m, _), before
                                       in zip(program.cuts, per_cut, befores)],
                                tol, jobs=jobs, reference=reference, progress=progress)
    links = [not r.ok and _in_links(r, own) for r, (_, own) in zip(results, per_cut)]
    return ProgramGate(results, labels, links)
