"""Pencil milling inside a CadQuery script: runs under CQ-editor and as a plain script.

A block with a round pocket (r 8 mm, 5 deep) and a step along one side: a 2 mm ball
cleans the pocket's floor-to-wall corner (one closed loop) and the step's corner.
``cadcnc.run`` takes the Workplane itself and a Pencil job; ``cadcnc.show_program`` shows
the program with ``show_object`` (``cadcnc.io.program_cq.to_cq`` gives its wires). Run:
``python docs/examples/pencil_example.py``.
"""

import cadquery as cq

import cadcnc
from cadcnc import Job, Pencil, Tool

block = (cq.Workplane("XY").box(40, 30, 12)
         .faces(">Z").workplane().center(-5, 0).circle(8).cutBlind(-5)
         .faces(">Z").workplane().center(22, 0).rect(6, 40).cutBlind(-4))

program = cadcnc.run(block, Job(Tool(radius=2.0), feed=1500.0, period=0.004,
                                operation=Pencil()))
totals = program.totals()
summary = (f"pencil R 2: {totals['cuts']} cuts, {totals['cut_length_mm']:.1f} mm cut, "
           f"{totals['link_length_mm']:.1f} mm of links, {totals['time_at_feed_s']:.1f} s "
           f"at feed; {len(program.skipped)} corners skipped")

if "show_object" in globals():  # CQ-editor: the part, the cuts (red), the links (blue)
    cadcnc.show_program(show_object, program, block)  # noqa: F821
else:
    print(summary)
    for s in program.skipped:
        print(f"  skipped faces {s.faces}: {s.reason}")
