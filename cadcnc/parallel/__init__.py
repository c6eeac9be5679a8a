"""Independent tasks on every core: the process pool (:mod:`.pool`, owned by a
``with kept_pools():`` block or by each call), a part's tasks on it (:mod:`.tasks`), and
the workers' server's warm-up (:mod:`.warm`, :mod:`.server`). No OCCT but the part's
bytes (:mod:`cadcnc.geometry.part_bytes`)."""
