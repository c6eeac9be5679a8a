"""A task that does nothing, for the scheduling overhead (importable by the workers)."""


def noop(k: int) -> int:
    return k
