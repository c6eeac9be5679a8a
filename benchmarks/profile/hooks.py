"""Stage timers and OCCT call counters installed as cadcnc's modules are imported.

Nothing in cadcnc changes: an import hook (``sys.meta_path``) wraps, right after a
module of ``STAGES`` or ``OCCT`` has run, the functions named there (so every module that
imports them by name gets the wrapper), and counts the CPU time of every import. A stage's
time is inclusive (``stretches`` holds ``limits`` and the guard calls made inside it); an
OCCT call is attributed to the innermost stage running it. CPU seconds
(``time.process_time``): run with ``--jobs 1``.
"""

from __future__ import annotations

import functools
import importlib.abc
import importlib.machinery
import sys
import time

STAGES = {   # stage name: (module, attribute path)
    "load": ("cadcnc.geometry.part", "load_step"),
    "run": ("cadcnc.ops.run", "run"),
    "setups": ("cadcnc.ops.pencil.fewest_setups", "pencil_setups"),
    "finish": ("cadcnc.ops.finish.raster", "raster_program"),
    "corners": ("cadcnc.ops.pencil.corners", "find_corners"),
    "stretches": ("cadcnc.ops.path.stretches", "pair_stretches"),
    "limits": ("cadcnc.ops.path.stretches", "locate_limit"),
    "stepping": ("cadcnc.ops.common", "run_stretch"),
    "guard.margin": ("cadcnc.guard.clearance", "ClearanceGuard.margin"),
    "guard.first_hit": ("cadcnc.guard.clearance", "ClearanceGuard.first_hit"),
    "guard.budget": ("cadcnc.guard.guard", "OperationGuard.budget"),
    "linking": ("cadcnc.ops.entries", "entered_program_segments"),
    "settle (cut-back)": ("cadcnc.pipeline.exit_policy", "settle"),
    "judge (gate)": ("cadcnc.pipeline.exit_policy", "judge"),
    "outputs": ("cadcnc.io.output_set", "OutputSet.write"),
}
"""Where missing in the code measured (an older tree), a stage is left out."""
OCCT = {   # module: the OCCT classes whose construction computes a distance there
    "cadcnc.guard.clearance": ("BRepExtrema_DistShapeShape",),
    "cadcnc.guard.moves": ("BRepExtrema_DistShapeShape",),
    "cadcnc.guard.face_distance": ("BRepExtrema_DistShapeShape", "BRepExtrema_ExtCF",
                                   "BRepExtrema_ExtPF"),
    "cadcnc.verification.probe": ("BRepExtrema_DistShapeShape",),
    "cadcnc.verification.planar": ("BRepExtrema_DistShapeShape",),
}
SLOW_S = 0.020
"""An OCCT call longer than this (CPU s) is listed with its caller."""
MAX_SLOW = 40

clock = time.process_time


class Report:
    """What the hooks measured: stage seconds and calls, imports, OCCT calls."""

    def __init__(self):
        self.stages: dict[str, list] = {}    # name: [seconds, calls]
        self.imports = 0.0
        self.occt: dict[str, list] = {}      # "module:class @ stage": [calls, seconds]
        self.slow: list[tuple] = []          # (seconds, where, detail)
        self.callers: dict[str, list] = {}   # "function face K kind": [calls, seconds]
        self.stack: list[str] = []
        self._importing = 0

    def as_dict(self) -> dict:
        top = sorted(self.callers.items(), key=lambda kv: -kv[1][1])[:12]
        return dict(stages=self.stages, imports=self.imports, occt=self.occt, callers=dict(top),
                    slow=sorted(self.slow, reverse=True)[:MAX_SLOW], slow_count=len(self.slow),
                    slow_seconds=sum(s[0] for s in self.slow))


REPORT = Report()


def _stage(name: str, fn):
    @functools.wraps(fn)
    def timed(*args, **kwargs):
        rec = REPORT.stages.setdefault(name, [0.0, 0])
        outer = name in REPORT.stack    # recursive: count the outermost call only
        REPORT.stack.append(name)
        t0 = clock()
        try:
            return fn(*args, **kwargs)
        finally:
            REPORT.stack.pop()
            if not outer:
                rec[0] += clock() - t0
            rec[1] += 1
    return timed


def _occt(module: str, cls_name: str, cls):
    def timed(*args):
        t0 = clock()
        out = cls(*args)
        dt = clock() - t0
        where = REPORT.stack[-1] if REPORT.stack else "-"
        rec = REPORT.occt.setdefault(f"{module.rsplit('.', 1)[-1]}:{cls_name} @ {where}",
                                     [0, 0.0])
        rec[0] += 1
        rec[1] += dt
        who = _caller()
        rec = REPORT.callers.setdefault(who, [0, 0.0])
        rec[0] += 1
        rec[1] += dt
        if dt > SLOW_S:
            REPORT.slow.append((dt, where, who))
        return out
    return timed


def _caller() -> str:
    """The cadcnc function that made a slow call, with its face number and kind if any."""
    f = sys._getframe(2)
    if f.f_code.co_name == "distance" and f.f_back is not None:   # guard/face_distance.py
        f = f.f_back
    k = f.f_locals.get("k")
    self = f.f_locals.get("self")
    kind = ""
    if k is not None and self is not None and hasattr(self, "_faces"):
        try:
            kind = " " + self._faces[k - 1].kind + (" (own)" if k in self.pair else "")
        except Exception:  # noqa: BLE001 - a description only
            kind = ""
    return f"{f.f_code.co_name} face {k}{kind}" if k is not None else f.f_code.co_name


def _patch(module) -> None:
    name = module.__name__
    for stage, (mod, attr) in STAGES.items():
        if mod != name:
            continue
        owner, *rest = attr.split(".")
        if not hasattr(module, owner):
            continue
        if rest:
            cls = getattr(module, owner)
            if rest[0] in vars(cls):
                setattr(cls, rest[0], _stage(stage, vars(cls)[rest[0]]))
        else:
            setattr(module, owner, _stage(stage, getattr(module, owner)))
    for cls_name in OCCT.get(name, ()):
        if hasattr(module, cls_name):
            setattr(module, cls_name, _occt(name, cls_name, getattr(module, cls_name)))


class _Loader(importlib.abc.Loader):
    def __init__(self, inner):
        self.inner = inner

    def create_module(self, spec):   # an extension module is built here
        t0 = clock()
        try:
            return self.inner.create_module(spec)
        finally:
            if REPORT._importing == 0:
                REPORT.imports += clock() - t0

    def exec_module(self, module):
        outer = REPORT._importing == 0
        REPORT._importing += 1
        t0 = clock()
        try:
            self.inner.exec_module(module)
        finally:
            REPORT._importing -= 1
            if outer:
                REPORT.imports += clock() - t0
        _patch(module)

    def __getattr__(self, name):   # get_code, get_source, is_package ... of the real loader
        return getattr(self.inner, name)


class _Finder(importlib.abc.MetaPathFinder):
    def find_spec(self, fullname, path, target=None):
        for finder in sys.meta_path:
            if finder is self:
                continue
            find = getattr(finder, "find_spec", None)
            spec = find(fullname, path, target) if find else None
            if spec is not None:
                if spec.loader is not None and not isinstance(spec.loader, _Loader):
                    spec.loader = _Loader(spec.loader)
                return spec
        return None


def install() -> Report:
    """Hook every later import (modules already imported are patched now)."""
    sys.meta_path.insert(0, _Finder())
    for module in list(sys.modules.values()):
        if getattr(module, "__name__", "").startswith("cadcnc"):
            _patch(module)
    return REPORT
