"""The stock simulation: a tri-dexel stock cut by programs, compared with the part
(docs/simulate.md). No OCCT here: the part comes in as triangles and exact distances from
:mod:`cadcnc.verification.stock_part`."""
