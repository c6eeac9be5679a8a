"""The guard stage: whether the ball and its shank are clear of the part (OCCT side).

Every operation asks one :class:`OperationGuard`, built by :func:`guard_for` from the job,
at each ball centre its stepper tries (:mod:`.guard`, with the proofs of :mod:`.cells`,
:mod:`.box_tree`, :mod:`.walls` and the closed forms of :mod:`.analytic`); links are
checked by :class:`~.moves.MoveClearance` (a straight move's swept ball and shank) and
refuted cheaply by :class:`~.stay_down.StayDown`. Lengths mm.
"""

from .clearance import ClearanceGuard
from .guard import FINISH_OWN_SHARE, PAIR_OWN_SHARE, OperationGuard, guard_for
from .moves import MoveClearance
from .stay_down import StayDown

__all__ = ["ClearanceGuard", "OperationGuard", "guard_for", "MoveClearance", "StayDown",
           "PAIR_OWN_SHARE", "FINISH_OWN_SHARE"]
