"""A program moved rigidly: every point and contact by ``p -> p @ R.T + t``, every normal by
``n -> n @ R.T``. A setup's program lives in its work coordinates; its JSON, CSV and
pictures are in part coordinates (:mod:`cadcnc.geometry.setup`). Lengths mm."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .program import CutSegment, LinkSegment, Program


def moved_program(program: Program, rotation: np.ndarray, shift: np.ndarray) -> Program:
    """A copy of ``program`` with points (N, 3) and contacts (N, 2, 3) moved to
    ``p @ rotation.T + shift`` and normals (N, 2, 3) turned by ``rotation`` (3, 3)."""
    r, t = np.asarray(rotation, float), np.asarray(shift, float)
    segments = []
    for seg in program.segments:
        if seg.kind == "cut":
            p = seg.path
            path = replace(p, points=p.points @ r.T + t, contacts=p.contacts @ r.T + t,
                           normals=p.normals @ r.T)
            segments.append(CutSegment(path, seg.edge, seg.stretch, seg.at_limit))
        else:
            segments.append(LinkSegment(seg.points @ r.T + t, seg.rapid.copy()))
    return Program(program.job, segments, list(program.skipped), list(program.notes))


def in_part_coordinates(program: Program, setup) -> Program:
    """A setup's ``program`` (work coordinates) in part coordinates (``setup``: a
    :class:`~cadcnc.geometry.setup.Setup`, or None: unchanged)."""
    if setup is None or setup.identity:
        return program
    return moved_program(program, setup.rotation.T, setup.origin)


def in_setup_coordinates(program: Program, setup) -> Program:
    """A ``program`` in part coordinates moved into the setup's work coordinates."""
    if setup is None or setup.identity:
        return program
    return moved_program(program, setup.rotation, -setup.rotation @ setup.origin)
