"""``python -m benchmarks profile``: each stage's CPU time and the OCCT distance calls
(count, time, the calls over 20 ms) of a cadcnc command run as a user runs it
(:mod:`.bench_profile`; :mod:`.hooks` times the stages, :mod:`.child` runs one command)."""
