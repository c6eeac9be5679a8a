"""The controller side: machine limits, the feed planned to them, the per-period stream.

No OCCT here (a test enforces it): the steppers that re-run a program's cuts on the part
come from the caller (:func:`cadcnc.ops.stream_steppers.stepper_factory`). The planner and
the stream (compiled code) are imported when first named, so that a command that only
reads a machine's limits (an operation's options) does not load them.
"""

from importlib import import_module

from .machine import Machine, read_machine_ini

__all__ = ["FeedPlan", "Machine", "Stream", "plan_feed", "read_machine_ini", "stream_program"]
_LAZY = {"FeedPlan": ".feed_plan", "plan_feed": ".feed_plan", "Stream": ".stream",
         "stream_program": ".stream"}


def __getattr__(name: str):
    """FeedPlan, plan_feed, Stream and stream_program from their modules, on first use."""
    if name in _LAZY:
        return getattr(import_module(_LAZY[name], __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
