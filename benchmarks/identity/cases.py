"""The identity cases: what every operation writes on the fixtures and the shared parts.

``FAST``: every operation once on a small fixture (the not-slow test); ``SLOW``: more
fixtures, options and strategies (the slow test); ``SHARED``: the ten public parts of
``/work/shared/parts`` (``python -m benchmarks identity --shared DIR``). Outputs are named
by the operation; every file a command writes is digested (pictures are not asked for).
"""

from __future__ import annotations

from dataclasses import replace

from .harness import Case

PROGRAM = ("-o", "program.json", "-o", "program.ngc")   # JSON and G-code
WITH_CSV = PROGRAM + ("-o", "program.csv")
STREAM = ("stream", "program.json", "-o", "stream.txt", "-o", "stream.npy")

BATCH_JOBS = """\
parts = ["step_block.step"]
outputs = [".json", ".ngc"]
out = "out"

[options]
radius = 3

[[operations]]
command = "pencil"

[[operations]]
command = "finish"
name = "finish-top"
faces = [7]
stepover = 4
"""

BOSS_APT = """\
PARTNO/'boss fillet pencil path'
PART = 'bspline_boss.step'
CUTTER/R=3, C=0
FEED/1500
PERIOD/4ms
BOSS = P/[F4, F5, EDGE, EDGE]
FINI
"""

SADDLE_APT = """\
PARTNO/'crossing cylinders saddle'
PART = 'crossing_cylinders.step'
CUTTER/R=3, C=0.2
FEED/1500
PERIOD/4ms
ROUGH1 = P/[F1, F2, EDGE(1), EDGE(1)]
CUTTER/R=3
FINISH1 = P/[F1, F2, EDGE(1), EDGE(1)]
FINISH2 = P/[F1, F2, EDGE(2), EDGE(2)]
FEED/3000
PERIOD/250us
PART3 = P/[F1, F2, EDGE, (5, 11.2, 22)]
FINI
"""


def path(name: str, part: str, faces: tuple[int, int], radius: float, *extra: str,
         outputs=PROGRAM, then=()) -> Case:
    command = ("path", "{part}", "--faces", str(faces[0]), str(faces[1]), "--radius",
               f"{radius:g}", *extra, *outputs)
    return Case(name, part, (command, *then))


def pencil(name: str, part: str, radius: float, *extra: str, outputs=PROGRAM,
           then=()) -> Case:
    return Case(name, part, (("pencil", "{part}", "--radius", f"{radius:g}", *extra,
                              *outputs), *then))


def finish(name: str, part: str, faces: tuple[int, ...], radius: float, *extra: str,
           outputs=PROGRAM, then=()) -> Case:
    command = ("finish", "{part}", "--faces", *map(str, faces), "--radius", f"{radius:g}",
               *extra, *outputs)
    return Case(name, part, (command, *then))


def pairs(name: str, part: str, faces: list[tuple[int, int]], radius: float,
          exits: tuple[int, ...] | None = None) -> Case:
    """``cadcnc path`` on each pair of one part, one program each."""
    commands = tuple(("path", "{part}", "--faces", str(i), str(j), "--radius", f"{radius:g}",
                      "-o", f"path-{i}-{j}.json", "-o", f"path-{i}-{j}.ngc")
                     for i, j in faces)
    return Case(name, part, commands, exits=exits)


FAST = [
    # corner path: a closed B-spline / cylinder corner, all three formats, then its stream
    path("path-bspline_boss-4-5", "bspline_boss.step", (4, 5), 3, outputs=WITH_CSV,
         then=(STREAM,)),
    # two stretches under an overhang, linked
    path("path-stretch_shelf-11-8", "stretch_shelf.step", (11, 8), 3),
    # a cut entered between its ends
    path("path-entry_middle-13-11", "entry_middle.step", (13, 11), 2),
    pencil("pencil-step_slot", "step_slot.step", 3, outputs=WITH_CSV),
    # the fewest setups: one program per setup chosen (P+Z.json, P+X.json, ...)
    Case("pencil-setups-six_pockets", "six_pockets.step",
         (("pencil", "{part}", "--radius", "2", "--setups", "auto", "-o", "P.json",
           "-o", "P.ngc"),)),
    finish("finish-raster-finish_slab", "finish_slab.step", (5,), 3, "--stepover", "2",
           outputs=WITH_CSV),
    finish("finish-waterline-wl_boss", "wl_boss.step", (9, 7, 2), 2, "--strategy",
           "waterline", "--stepdown", "2"),
    finish("finish-steep-shallow-wl_wall", "wl_wall.step", (5,), 3, "--strategy",
           "steep-shallow", "--scallop", "0.2", "--overlap", "0.5"),
    # an APT-like part program
    Case("run-apt-bspline_boss", "bspline_boss.step",
         (("run", "boss.apt", "-o", "boss.ngc", "-o", "boss.json"),),
         files=(("boss.apt", BOSS_APT),)),
    # a job file on a local Dask cluster of one worker: the programs, and the summary
    # (summary.csv repeats summary.json; batch-part.json holds the re-run key, a hash
    # of Python reprs and the version, and the records again)
    Case("batch-step_block", "step_block.step",
         (("batch", "jobs.toml", "--workers", "1"),), files=(("jobs.toml", BATCH_JOBS),),
         ignore=("out/summary.csv", "out/step_block/batch-part.json"),
         normalise=(("out/summary.json", "batch-summary"),
                    ("out/step_block/pencil.json", "folder"),
                    ("out/step_block/finish-top.json", "folder"))),
]

SLOW = [
    # every concave pair of the fixtures of fixtures.json, R 3 (narrow_slot's are refused,
    # exit 3; torus_cone's second corner too: the shank)
    pairs("paths-crossing_cylinders", "crossing_cylinders.step", [(1, 2)], 3),
    pairs("paths-sphere_cylinder", "sphere_cylinder.step", [(1, 2)], 3),
    pairs("paths-torus_cone", "torus_cone.step", [(1, 2), (4, 5)], 3, exits=(0, 3)),
    pairs("paths-pocket", "pocket.step", [(7, 16), (8, 17), (9, 17), (10, 17), (11, 17),
                                          (12, 17), (13, 17), (14, 17), (15, 17)], 3),
    pairs("paths-fillet_block", "fillet_block.step", [(8, 10)], 3),
    pairs("paths-ramp_wall", "ramp_wall.step", [(3, 7), (3, 8), (3, 9), (3, 10)], 3),
    pairs("paths-ellipse_pocket", "ellipse_pocket.step", [(7, 8)], 3),
    pairs("paths-dome_pole", "dome_pole.step", [(3, 7)], 3),
    # R 5 in the ellipse, tighter than the ball at its ends: the gate refuses it (exit 5),
    # written anyway
    Case("path-ellipse_pocket-R5-allow-gouge", "ellipse_pocket.step",
         (("path", "{part}", "--faces", "7", "8", "--radius", "5", "--allow-partial",
           "--allow-gouge", *PROGRAM),), exits=(5,)),
    # the entry fixtures
    path("path-entry_end-10-8", "entry_end.step", (10, 8), 2),
    path("path-entry_side-9-7", "entry_side.step", (9, 7), 2),
    # stretch fixtures
    path("path-stretch_pocket-11-8", "stretch_pocket.step", (11, 8), 3),
    path("path-stretch_sloped-8-2", "stretch_sloped.step", (8, 2), 3),
    path("path-stretch_boss-1-6", "stretch_boss.step", (1, 6), 3),
    # pieces of real parts: a torus fillet tighter than a 2 mm ball, tool axis -Z
    path("path-r0901_fillet-16-18", "r0901_fillet.step", (16, 18), 2, "--allow-partial"),
    path("path-r0901_near_tangent-axis-Z", "r0901_near_tangent.step", (20, 21), 3,
         "--axis", "-Z"),
    path("path-r0901_reversed-axis-Z", "r0901_reversed.step", (23, 15), 3, "--axis", "-Z"),
    # surface models: loose faces sewn
    path("path-surf_boss_faces-4-5", "surf_boss_faces.step", (4, 5), 3),
    # options: tool tip, spindle, clearance, plunge feed, feed, period, allowance
    path("path-bspline_boss-options", "bspline_boss.step", (4, 5), 3, "--tool-tip",
         "--spindle", "12000", "--clearance", "60",
         "--plunge-feed", "300", "--feed", "3000", "--period", "2ms", "--allowance",
         "0.25"),
    # the stream at a replaced feed and jerk (default machine); pencil's own --stream
    path("path-bspline_boss-stream-feed", "bspline_boss.step", (4, 5), 3,
         then=(("stream", "program.json", "--feed", "10000", "--jerk", "20000", "-o",
                "stream.npy"),)),
    pencil("pencil-step_block-stream-option", "step_block.step", 3, "--stream",
           "stream.npy"),
    pencil("pencil-fillet_pocket", "fillet_pocket.step", 3),
    pencil("pencil-pocket-R2-allowance", "pocket.step", 2, "--allowance", "0.5"),
    # G-code points dropped within 0.01 mm, the tip programmed; the other direction
    pencil("pencil-step_block-conventional-tolerance", "step_block.step", 3, "--side",
           "conventional", "--faces", "3", "8", "--tolerance", "0.01", "--tool-tip"),
    pencil("pencil-surf_sheet", "surf_sheet.step", 3),
    pencil("pencil-six_pockets-axis+X", "six_pockets.step", 2, "--axis", "+X"),
    Case("pencil-setups-six_pockets-list", "six_pockets.step",
         (("pencil", "{part}", "--radius", "2", "--setups", "-X,+Z,+Y", "--setup-overlap",
           "1", "-o", "P.json", "-o", "P.ngc"),)),
    finish("finish-raster-finish_slab-stepover1", "finish_slab.step", (5,), 3,
           "--stepover", "1"),
    finish("finish-raster-finish_boss", "finish_boss.step", (6,), 3, "--stepover", "1"),
    finish("finish-raster-finish_hole", "finish_hole.step", (5,), 3, "--stepover", "2"),
    finish("finish-raster-finish_fillet-scallop", "finish_fillet.step", (6, 3), 3,
           "--scallop", "0.05"),
    finish("finish-raster-finish_ridge-oneway-angle", "finish_ridge.step", (3, 4), 3,
           "--stepover", "1", "--pattern", "oneway", "--angle", "30"),
    finish("finish-raster-finish_valley", "finish_valley.step", (3, 4), 3, "--stepover",
           "1"),
    finish("finish-raster-finish_rounded", "finish_rounded.step", (3, 5, 7), 3,
           "--stepover", "1"),
    finish("finish-raster-finish_slab-axis", "finish_slab.step", (5,), 3, "--stepover", "2",
           "--axis", "0.1,0,1"),
    finish("finish-waterline-wl_dome", "wl_dome.step", (5,), 3, "--strategy", "waterline",
           "--stepdown", "1"),
    finish("finish-waterline-wl_wall-conventional", "wl_wall.step", (5,), 3, "--strategy",
           "waterline", "--scallop", "0.1", "--side", "conventional"),
    finish("finish-steep-shallow-wl_boss", "wl_boss.step", (9, 7, 2), 2, "--strategy",
           "steep-shallow", "--stepover", "1", "--stepdown", "1"),
    finish("finish-steep-shallow-wl_dome-stepover", "wl_dome.step", (5,), 3, "--strategy",
           "steep-shallow", "--stepover", "2", "--stepdown", "2", "--threshold", "60"),
    Case("run-apt-saddle", "crossing_cylinders.step",
         (("run", "saddle.apt", "-o", "saddle.ngc", "--tool-tip"),
          ("run", "saddle.apt", "-o", "saddle.json")),
         files=(("saddle.apt", SADDLE_APT),)),
]

# The ten public parts (/work/shared/parts, OCCT's test data): pencil at R 3 on each
# (several are refused, exit 3: no corner a +Z ball reaches; the exit code is the
# record), R 2 on five; the fewest setups on four; a corner path and its stream; raster,
# waterline and steep-and-shallow finishing on the screw (tool axis -Z) and the bracket.
# bug28414's waterline: 31 cuts, exit 0 (a Python error, exit 1, at 4ba2bdd; 129 s of CPU
# before the torus's shank distance in closed form, 19 s after).
L_BRACKET = "bug3883_xr2-ct-214_l-bracket.stp"
LEVER = "bm2_ec_lever-A.stp"
ABC = "bug32596_abc_0_13.step"
TORUS = "bug28414_bug_toroidal_surface.stp"
SHARED_PARTS = {"screw": "screw.step", "l-bracket": L_BRACKET, "tr8_bv1_ct": "tr8_bv1_ct.stp",
                "lever": LEVER, "exhaust": "bm2_ec_exhaust-A.stp", "abc": ABC,
                "piattello": "bug27453_165-174_piattello.stp", "r0901": "r0901_ec.stp",
                "box-openshell": "bug25169_box-openshell.stp", "toroidal": TORUS}
NOTHING_AT_R3 = {"screw", "tr8_bv1_ct", "exhaust", "box-openshell", "toroidal"}


def _refused(case: Case) -> Case:
    """``case`` expected to exit 3 (nothing to cut), writing nothing."""
    return replace(case, exits=(3,))


def _pencil_r3(key: str, part: str) -> Case:
    case = pencil(f"shared-pencil-{key}-R3", part, 3)
    return _refused(case) if key in NOTHING_AT_R3 else case


SHARED = [
    *[_pencil_r3(key, part) for key, part in SHARED_PARTS.items()],
    pencil("shared-pencil-l-bracket-R2", L_BRACKET, 2),
    pencil("shared-pencil-lever-R2", LEVER, 2),
    pencil("shared-pencil-abc-R2", ABC, 2),
    pencil("shared-pencil-piattello-R2", SHARED_PARTS["piattello"], 2),
    pencil("shared-pencil-r0901-R2", SHARED_PARTS["r0901"], 2),
    pencil("shared-pencil-screw-R1", "screw.step", 1),
    pencil("shared-pencil-screw-R3-axis-Z", "screw.step", 3, "--axis", "-Z"),
    Case("shared-setups-screw-R3", "screw.step",
         (("pencil", "{part}", "--radius", "3", "--setups", "auto", "-o", "P.json",
           "-o", "P.ngc"),)),
    Case("shared-setups-l-bracket-R3", L_BRACKET,
         (("pencil", "{part}", "--radius", "3", "--setups", "auto", "-o", "P.json",
           "-o", "P.ngc"),)),
    Case("shared-setups-lever-R3", LEVER,
         (("pencil", "{part}", "--radius", "3", "--setups", "auto", "-o", "P.json",
           "-o", "P.ngc"),)),
    Case("shared-setups-abc-R3", ABC,
         (("pencil", "{part}", "--radius", "3", "--setups", "auto", "-o", "P.json",
           "-o", "P.ngc"),)),
    path("shared-path-l-bracket-15-16", L_BRACKET, (15, 16), 3, outputs=WITH_CSV,
         then=(STREAM,)),
    pairs("shared-paths-lever", LEVER, [(19, 33), (31, 40)], 3, exits=(0, 3)),
    finish("shared-finish-raster-l-bracket-1", L_BRACKET, (1,), 3, "--stepover", "3"),
    finish("shared-finish-raster-l-bracket-16", L_BRACKET, (16,), 3, "--stepover", "3"),
    finish("shared-finish-raster-screw-7-axis-Z", "screw.step", (7,), 1, "--axis", "-Z",
           "--stepover", "0.5"),
    finish("shared-finish-waterline-screw-8-axis-Z", "screw.step", (8,), 1, "--axis", "-Z",
           "--strategy", "waterline", "--stepdown", "1"),
    Case("shared-finish-steep-shallow-screw-axis-Z", "screw.step",
         (("finish", "{part}", "--faces", "7", "8", "--radius", "1", "--axis", "-Z",
           "--strategy", "steep-shallow", "--stepover", "0.5", "--stepdown", "1",
           "--allow-partial", *PROGRAM),), exits=(6,)),
    # 18 cuts, exit 0 (2026-11-29: exit 3 while every guide plane, centred on the origin,
    # missed the part at z 114-161; then exit 5 while the guard took OCCT's wrong shank
    # distance to this torus: docs/notes/guard-calls.md; re-recorded 2026-11-30 with the
    # torus's shank distance in closed form: its JSON's points within 5e-13 mm, the G-code
    # the same bytes, as r0901's pencil at R 2, within 7e-15 mm)
    finish("shared-finish-raster-toroidal", TORUS, (1,), 3, "--stepover", "2"),
    finish("shared-finish-waterline-toroidal", TORUS, (1,), 3, "--strategy", "waterline",
           "--stepdown", "2"),
]

GROUPS = {"fast": FAST, "slow": SLOW, "shared": SHARED}
