"""The controller side: machine limits, the feed planned to them, the per-period stream.

No OCCT here (a test enforces it): the steppers that re-run a program's cuts on the part
come from the caller (:func:`cadcnc.ops.stream_steppers.stepper_factory`).
"""

from .feed_plan import FeedPlan, plan_feed
from .machine import Machine, read_machine_ini
from .stream import Stream, stream_program

__all__ = ["FeedPlan", "Machine", "Stream", "plan_feed", "read_machine_ini", "stream_program"]
