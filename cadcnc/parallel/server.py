"""The workers' server's last preload (:data:`.pool.PRELOAD`); no library module imports it.

A forkserver can only import modules before it forks workers, so loading the compiled
kernels there is an import: this one loads those of every cadcnc module the server
imported before it (:func:`.warm.warm`), once, so that each worker starts with them.
"""

from .warm import warm

LOADED = warm()
"""How many compiled signatures were loaded."""
