"""Controller benchmarks: the stream's planning cost, its feed plot, LinuxCNC's planner beside it."""
