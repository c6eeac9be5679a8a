"""Benchmarks of the setups (issue 23): coverage from every principal axis, the fewest setups."""
