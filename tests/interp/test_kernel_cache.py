"""A changed kernel source drops the whole compiled cache (numba sees only the own file)."""

from __future__ import annotations

import cadcnc.interp.kernel as kernel


def test_a_changed_source_drops_the_cached_code(tmp_path, monkeypatch):
    pkg = tmp_path / "kernel"
    (pkg / "__pycache__").mkdir(parents=True)
    (pkg / "a.py").write_text("x = 1\n")
    monkeypatch.setattr(kernel, "_HERE", pkg)
    kernel._drop_stale_cache()                      # first stamp
    cached = pkg / "__pycache__" / "a.f-1.py311.nbi"
    cached.write_text("compiled")
    kernel._drop_stale_cache()                      # same sources: the cache stays
    assert cached.exists()
    (pkg / "a.py").write_text("x = 2\n")            # a callee edited
    kernel._drop_stale_cache()
    assert not cached.exists()
    assert (pkg / "__pycache__" / kernel._STAMP).exists()
