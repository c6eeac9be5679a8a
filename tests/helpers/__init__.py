"""What the test modules share (the repository's fixtures, the command run in process, small
judges of programs): imported as ``helpers.<module>``; ``pyproject.toml`` puts ``tests/`` on
the path. Independent references (closed forms, OCCT, rs274, TOPP-RA) are
:mod:`cadcnc.testing`, shared with the benchmarks."""
