"""Raster finishing inside a CadQuery script: runs under CQ-editor and as a plain script.

A block whose two long top edges are rounded (r 4 mm): a 2 mm ball finishes the top and
both rounds in zigzag passes along them, 1 mm apart. ``cadcnc.finish`` takes the
Workplane and a Workplane selection of its faces; ``cadcnc.show_program`` shows the
program with ``show_object`` (``cadcnc.io.program_cq.to_cq`` gives its wires). Run:
``python docs/examples/finish_example.py``.
"""

import cadquery as cq

import cadcnc

block = cq.Workplane("XY").box(30, 20, 10).edges("|X and >Z").fillet(4)

program = cadcnc.finish(block, block.faces(">Z or %CYLINDER"), radius=2.0, stepover=1.0)
totals = program.totals()
summary = (f"finish R 2: {totals['cuts']} cuts, {totals['cut_length_mm']:.1f} mm cut, "
           f"{totals['link_length_mm']:.1f} mm of links, {totals['time_at_feed_s']:.1f} s "
           f"at feed")

if "show_object" in globals():  # CQ-editor: the part, the cuts (red), the links (blue)
    cadcnc.show_program(show_object, program, block)  # noqa: F821
else:
    print(summary)
    for note in program.notes:
        print(f"  {note}")
