"""Byte identity of cadcnc's programs: benchmarks/identity/README.md."""
