"""Batches of parts on Dask distributed (docs/batch.md): :func:`batch` runs each part's
operations as one task on an embedded local cluster or an existing one, writes each
part's outputs to its own folder and returns the summary's records.

:func:`cadcnc.batch.batch` is the entry (``from cadcnc.batch import batch``); the modules
are ``cadcnc.batch.engine`` and so on.
"""

from __future__ import annotations


def batch(parts, out, **options):
    """The records of a batch: :func:`cadcnc.batch.engine.batch` (same arguments)."""
    from .engine import batch as run  # Dask and OCCT: about 3 s `import cadcnc` does not pay

    return run(parts, out, **options)


__all__ = ["batch"]
