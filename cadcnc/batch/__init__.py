"""Batches of parts on Dask distributed (docs/batch.md): :func:`~cadcnc.batch.engine.run_batch`
(``cadcnc.run_batch``) runs each part's operations as one task on an embedded local cluster
or an existing one, writes each part's outputs to its own folder and returns the summary's
records; :mod:`~cadcnc.batch.job_file` reads a batch's job file.

Nothing is imported here: Dask and OCCT take about 3 s, which ``import cadcnc`` does not pay.
"""
