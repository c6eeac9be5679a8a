"""The demo (``cadcnc demo``): the main job on the bundled part, verified, with every
output, and every corner of the part in one pencil program."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

from ..core.errors import EXIT_GOUGE, OutputError, StepFileError
from ..core.job import Job, PairPath, Pencil, Tool
from ..geometry.part import load_step
from ..io.gcode import blend_for
from ..io.output_set import OutputSet
from ..io.outputs import SUFFIXES, render
from ..ops.common import single_cut_program
from ..ops.path.pair_path import path_for_job
from ..verification import verify
from .exit_policy import judge
from .program_plan import plan

FIXTURE = "bspline_boss.step"
FACES = (4, 5)  # the B-spline top and the cylindrical boss
JOB = Job(Tool(3.0), feed=1500.0, period=0.004, operation=PairPath(faces=FACES))


def demo_step() -> Path:
    """The bundled demo part: package data if shipped, else the source tree's fixtures."""
    pkg = Path(__file__).resolve().parents[1]
    for candidate in (pkg / "data" / FIXTURE, pkg.parent / "fixtures" / FIXTURE):
        if candidate.is_file():
            return candidate
    raise StepFileError(f"the demo part {FIXTURE} is not installed (looked in "
                        f"{pkg / 'data'} and {pkg.parent / 'fixtures'})")


def demo_program(step: Path, job: Job) -> str:
    """The demo job as an APT-like program."""
    i, j = job.operation.faces
    return (f"$$ the demo job as an APT-like program: cadcnc run demo.apt -o demo.ngc\n"
            f"PARTNO/'cadcnc demo'\nPART = '{step}'\n"
            f"CUTTER/R={job.tool.radius:g}, C={job.tool.allowance:g}\nFEED/{job.feed:g}\n"
            f"PERIOD/{job.period * 1000:g}ms\nBOSS = P/[F{i}, F{j}, EDGE, EDGE]\nFINI\n")


FILES = ("path.json", "path.csv", "path.ngc", "demo.apt", "verification.txt",
         "verification.json", "path.png", "pencil.json", "pencil.png")


def run_demo(out, say, progress=None) -> int:
    """Run the demo into the folder ``out``; ``say(text)``: its narrative for the user,
    ``progress``: the path's ``Progress`` (cycles, 0, the distance). The exit code."""
    step = demo_step()
    out = Path(out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise OutputError(f"{out}: cannot create the demo folder ({e.strerror})") from e
    outputs = OutputSet([out / name for name in FILES], SUFFIXES + (".apt", ".txt"),
                        inputs=[step])
    job = replace(JOB, source=str(step))
    i, j = job.operation.faces
    say(f"cadcnc demo: faces {i} (B-spline top) and {j} (cylindrical boss) of {step}")
    part = load_step(step)
    tp = path_for_job(part, job, progress=progress)
    program = single_cut_program(part, job, tp)
    say(program.summary(step.name))
    report = verify(tp, part)
    d = report.to_dict()
    say(f"  verified   max over-cut {d['max_overcut_mm']:.3g} mm, max under-cut "
        f"{d['max_undercut_mm']:.3g} mm, Hausdorff to OCCT {d['hausdorff_mm']:.3g} mm")
    verdict = judge(program, part, "cadcnc: demo", gcode=dict(blend=blend_for(
        job.tolerances.gouge)))
    for line in verdict.messages:
        say(line)
    title = f"demo: faces {i} {j} of {step.name}"
    contents = {out / name: render(program, name, part, title,
                                   **(dict(blend=blend_for(job.tolerances.gouge))
                                      if name.endswith(".ngc") else {}))
                for name in ("path.json", "path.csv", "path.ngc", "path.png")}
    contents[out / "demo.apt"] = demo_program(step, job)
    contents[out / "verification.txt"] = report.format_table() + "\n"
    contents[out / "verification.json"] = json.dumps(d, indent=1) + "\n"
    pen = plan(part, replace(job, operation=Pencil()))  # every corner of the part, linked
    say(f"pencil R {job.tool.radius:g}: {len(pen.cuts)} cuts, {pen.cut_length:.1f} mm cut, "
        f"{pen.link_length:.1f} mm of links, {len(pen.skipped)} corners skipped")
    contents[out / "pencil.json"] = render(pen, "pencil.json")
    contents[out / "pencil.png"] = render(pen, "pencil.png", part, f"demo: pencil of {step.name}")
    outputs.write(contents)
    say(f"wrote {out}/: " + ", ".join(sorted(FILES)))
    return verdict.code if report.ok() else EXIT_GOUGE
