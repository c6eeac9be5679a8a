"""``cadcnc batch`` on Dask: throughput with 1 and 2 workers, overhead per task
(``throughput.py``)."""
