"""The compiled interpolation kernel: numpy, numba and math only, no OCCT.

Compiled functions are cached on disk (numba ``cache=True``) in this folder's
``__pycache__``. numba checks a cached function against its own file only, not against
the functions it calls in other files: after an update of any module here, a cached
caller could keep running the old code of a callee. So, before any module of the kernel
is imported, :func:`_drop_stale_cache` compares a hash of every source file here (the
trim-grid reader included) with the one stamped beside the cache, and deletes the cached code when they differ (numba then
compiles afresh, once).

Every kernel function (the trim-grid reader included) is compiled with ``_nrt=False``: no
reference counting. The kernel allocates nothing, and with NRT on, each array slice or
reshape handed from one compiled function to another costs an atomic increment and
decrement, about half of a cycle's time (0.5-0.6 us of 1.1-1.5 us). Without NRT an
allocation in the kernel is a compile error.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

_HERE = Path(__file__).resolve().parent
_STAMP = "sources.sha256"


def _drop_stale_cache() -> None:
    """Delete this folder's numba cache when any kernel source changed since it was made."""
    cache = _HERE / "__pycache__"
    digest = hashlib.sha256()
    for src in sorted(_HERE.glob("*.py")):
        digest.update(src.name.encode() + b"\0" + src.read_bytes())
    stamp = digest.hexdigest()
    try:
        if (cache / _STAMP).read_text() == stamp:
            return
        for old in list(cache.glob("*.nbi")) + list(cache.glob("*.nbc")):
            old.unlink(missing_ok=True)
        (cache / _STAMP).write_text(stamp)
    except OSError:  # no cache folder yet, or a read-only installation: nothing stale kept
        try:
            cache.mkdir(exist_ok=True)
            (cache / _STAMP).write_text(stamp)
        except OSError:
            pass


_drop_stale_cache()
