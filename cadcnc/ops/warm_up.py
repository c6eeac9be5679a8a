"""Imported by the workers' server only (:data:`cadcnc.workers.PRELOAD`, after the
library): loads the compiled kernels once (:func:`cadcnc.ops.warm.warm`), before the
server forks any worker."""

from .warm import warm

LOADED = warm()
"""How many compiled signatures were loaded."""
