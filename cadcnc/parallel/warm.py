"""Compiled kernels loaded before a worker's first task.

numba loads each compiled function from its on-disk cache (``cache=True``) at its first
call: about 1.5 s for a process's first finishing plane or pencil corner, which every
worker would pay again at its first task. The workers' server imports
:mod:`.server` (:data:`.pool.PRELOAD`), which runs :func:`warm` once, so every worker
forked from the server starts with them loaded.

numba keeps no public list of a function's cached signatures: its index file is read
through the dispatcher's cache object (numba 0.60 to 0.68), and only entries compiled
for this machine and this very code are loaded, so nothing is compiled afresh. Any
failure leaves that function to load at its first call, as without warm-up: nothing here
changes an answer.
"""

from __future__ import annotations

import sys

from numba.core.dispatcher import Dispatcher


def warm() -> int:
    """Load the cached compiled code of every numba function of the cadcnc modules
    imported so far; how many signatures were loaded."""
    count = 0
    for name, module in list(sys.modules.items()):
        if name == "cadcnc" or name.startswith("cadcnc."):
            for value in list(vars(module).values()):
                if isinstance(value, Dispatcher) and value.__module__ == name:
                    count += load_cached(value)
    return count


def load_cached(function: Dispatcher) -> int:
    """Load every signature of ``function`` found in its cache for this machine and
    code (see the module doc); how many."""
    try:
        cache = function._cache
        index = cache._cache_file._load_index()
        codegen = function.targetctx.codegen()
    except Exception:  # noqa: BLE001 - no cache, or another numba: nothing to warm
        return 0
    count = 0
    for key in list(index):
        try:
            if key != cache._index_key(key[0], codegen):
                continue   # another machine's or an older version's: never compile here
            function.compile(key[0])
        except Exception:  # noqa: BLE001 - left to load (or compile) at its first call
            continue
        count += 1
    return count
