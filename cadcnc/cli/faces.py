"""``cadcnc faces``: a part's faces, neighbours and concave pairs
(:func:`cadcnc.pipeline.part_faces.faces_of`), printed. It reads the part only: neither the
interpolation core nor numba is imported, so it starts fast."""

from __future__ import annotations

import json

from cadcnc.geometry.faces_report import concave_edges
from cadcnc.pipeline.part_faces import faces_of

from .feedback import say_error


def faces(args) -> int:
    data, warnings = faces_of(args.step, args.flip_material)
    for line in warnings:
        say_error(f"cadcnc: faces: OCCT's STEP reader: {line}")
    if args.json:
        print(json.dumps(data, indent=1))
        return 0
    _print_faces(args.step, data)
    return 0


def _print_faces(step, data: dict) -> None:
    """The faces table and the concave pairs, for people."""
    print(f"{step}: {data['n_faces']} faces; material side: {data['material']['rule']}")
    if data["material"].get("sewing"):
        sewn = data["material"]["sewing"]
        print(f"sewn at {sewn['tolerance_mm']:g} mm: largest edge tolerance "
              f"{sewn['max_edge_tolerance_mm']:.3g} mm, {sewn['free_edges']} free edges")
    print(f"{'face':>4}  {'kind':<10} {'area mm^2':>11}  neighbours: face class "
          "material-angle deg")
    for f in data["faces"]:
        nb = ", ".join(f"{n['face']} {n['class']} {_angles(n['angle_deg'])}"
                       for n in f["neighbours"])
        print(f"{f['number']:>4}  {f['kind']:<10} {f['area_mm2']:>11.2f}  {nb}")
    if not data["concave_pairs"]:
        print("\nno concave pairs: no two faces meet in an inner corner a ball can follow")
        return
    print("\nconcave pairs, the candidates for `cadcnc path --faces I J` "
          "(a ball can sit in these corners):")
    for i, j, k, e in concave_edges(data):
        print(f"  {i:>3} {j:<3}  edge {k}: {'closed' if e['closed'] else 'open'}, "
              f"{e['length_mm']:.3f} mm, material angle {_angles(e['angle_deg'])} deg")


def _angles(rng) -> str:
    lo, hi = rng
    return f"{lo:.1f}" if abs(hi - lo) < 0.05 else f"{lo:.1f}..{hi:.1f}"
