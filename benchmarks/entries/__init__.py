"""Entries through free space (docs/program.md "Entries"): the independent check of links and of
`unreachable` skips (``sweeps.py``), and the measurement on the pairs of issue 23
(``pairs.py``)."""
