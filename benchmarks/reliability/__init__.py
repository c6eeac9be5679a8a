"""Reliability benchmarks: long fuzz runs judged independently against OCCT."""
