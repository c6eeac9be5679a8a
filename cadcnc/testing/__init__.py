"""Independent references the tests and the benchmarks judge cadcnc by (like ``numpy.testing``).

Each shares no code with what it judges: closed forms, OCCT's own distances and
classifiers, LinuxCNC's rs274, TOPP-RA. The last stage of the package: nothing in cadcnc
imports it (tests/test_architecture.py).

- ``coverage_oracle``, ``coverage_sewing``: feasible ball positions along concave edges;
- ``moves_judge``: the ball's depth into the part along written moves;
- ``tool_sweeps``: the tool swept along a straight move, against every face;
- ``contour_reference``: the true contour error of sampled positions;
- ``topp_bound``: the time-optimal v/a bound of a program (TOPP-RA, ``toppra``);
- ``rs274``: LinuxCNC's G-code interpreter read back;
- ``occt``: OCCT's distance from a point to a shape.
"""
