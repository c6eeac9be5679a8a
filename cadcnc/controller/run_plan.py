"""One run's feed, planned near time-optimally to the axes' velocity,
acceleration and jerk limits.

The path p(s) is fixed; the plan chooses only s(t). Per axis i, with T = p', K = p'',
D = p''' (in arc length, from the kernel's points):

- velocity      |T_i v|                                  <= V_i
- acceleration  |T_i s'' + K_i v^2|                      <= A_i
- jerk          |T_i s''' + 3 K_i v s'' + D_i v^3|        <= J_i

each used where it binds, at MARGIN of the limit. A run (:mod:`.runs`) is moved through
from rest to rest:

1. the speed limits: the feed, V_i / |T_i|, the jerk's D_i v^3 term (D_SHARE of J_i;
   where that term binds, the run is also planned at D_SHARE_HIGH, the faster kept; a
   run that bends there first, as it mostly wins and then lets the others give up), and
   the one-period jolt of a curvature jump or a join (``runs.JOIN_SHARE``);
2. the time-optimal profile under the acceleration limits (:func:`.topp.passes`), with
   the jerk's Coriolis term 3 K_i v s'' within CORIOLIS_SHARE of J_i;
3. that s(t) averaged over a moving window W: its jerk T_i (s''(t) - s''(t - W)) / W,
   W the shortest that leaves every axis the room the curvature terms do not take
   (:func:`.topp.window_needed`; about A / J on a straight run, once per rest);
4. the speed limits eroded (each held over +-v W) and the derivatives taken over the
   window's reach, so that the averaged motion keeps every limit where it is;
5. on a run that bends, the averaged motion's jerk measured as it is
   (:mod:`.averaged_jerk`) rather than bounded from the window's extremes: the run is
   planned at BENT_SHARE of J for the Coriolis term (at most 1 - the D share -
   BENT_ROOM), its window grown only as much as
   the measured jerk asks (from the second growth on, where the secant of the measured
   share through the last two windows reaches 1: :func:`_secant`; and, where it grew,
   its top speed also capped at CAP_FACTORS of the plan's, the faster kept);
6. on a run that bends, once the best of the above is known, a *measured* plan with its
   acceleration and D share (:func:`_measured_window`): the axes' velocity and D v^3
   limits where they are and the path's derivatives at each point (no reach; the
   programmed speed and the joins' jolts still held over it), the averaged motion's
   velocity, acceleration and jerk all measured (:func:`.averaged_jerk.shares`), the
   limits scaled down where it goes over; kept where faster. The run's grid may not
   resolve the path where p''' is large (a tight curl), which only the held limits and
   boxes covered: the stream's own check decides, and a stream it finds over a limit is
   planned again with no measured plan (:func:`.stream.stream_program`).

A plan tried against another is given up as soon as one of its rounds lasts as long
(:class:`_Slower`): its rounds only get longer. Only plans that no later plan depends on
give up (a capped plan, a next Coriolis share), so the chosen plan is the one planning
every way in full would choose (tested). The acceleration used is at most
sqrt(V J) per axis, and (J² L)^(1/3) on a run of length L: with more, the window would
cost more time than the acceleration saves, and a looser limit could lengthen the plan.
Times s, lengths mm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core.errors import EXIT_GOUGE, CadcncError
from . import averaged_jerk, plan_once, reach, topp
from .machine import Machine
from .profile import Profile
from .runs import JOIN_SHARE, Run

MARGIN = 0.995
"""Share of every limit the plan uses; the rest covers the path's derivatives between the
kernel's points, the averaged squared speed (v² of the mean is at most the mean of v²)
and the kernel's step landing within a few nm of the plan."""
CORIOLIS_SHARE = 0.25   # of J_i: 3 K_i v s'' at most where the window's bound judges the
                        # jerk (larger shares only lengthened its window)
D_SHARE = 0.25          # of J_i: D_i v^3 at most
D_SHARE_HIGH = 0.6      # ... or this much, on a run where that term binds the speed (a
                        # path with a large p''' cruising: more speed, a longer window),
                        # the faster kept
SHARE_STEP, SHARE_STEPS = 0.025, 3   # the Coriolis share searched per curved run
BENT_SHARE = 0.65       # of J_i for 3 K_i v s'' on a run that bends (its jerk measured):
                        # the arcs' durations fall up to about 0.65 and are flat beyond
BENT_ROOM = 0.025       # ... at most what leaves this much of J_i beside the D v³ share
                        # (0.375 at D_SHARE_HIGH: one plan where a search of 0.025 steps
                        # from 0.25 took five; shorter on 8 of the 9 streams it changed)
CAP_FACTORS = (0.95,)   # a bending run whose window grew: also its top speed capped at
                        # these shares of its plan's
WINDOW_GROWTH = 1.02    # a bending run's window lengthened by at least this factor a round
SECANT_OVER = 1.0005   # a window grown by the secant: this much past where it predicts 1
SECANT_GROWTH = 1.002  # and at least this much longer than the last
WINDOW_ROUNDS = 32      # plans of a run at most: turns flattened, or the window grown
FLATTEN_ROUNDS = 16     # of which at most this many flatten turns
TIGHTEN_ROUNDS = 2      # plans with the derivatives taken where the motion goes
TIGHTEN_SLACK = 0.1     # the ranges assumed: those of the last plan, widened this much
TIE = 1e-12            # plans of a run whose durations agree within this share are a tie:
                       # the first kept (which one an early give-up skips is then moot)
SCALE_OVER = 5e-4       # a measured plan over a velocity or acceleration limit: its limits
SCALE_ROUNDS = 4        # scaled by the share over and this much more, at most this often
NEED_ROUNDOFF = 1e-7    # a window the plan needs to within this share of itself suffices
                        # (round-off; MARGIN covers it), and flattening that shortens the
                        # need by less is no progress: no plan made again for round-off


class _Slower(Exception):
    """A plan given up once it can no longer beat the one it is to beat: each round of
    :func:`_windowed` only lowers the speed limits or lengthens the window, so a round's
    duration is a lower bound of the plan's."""


class PlanError(CadcncError):
    """No stream within the machine's limits: nothing is written (names the run or the
    period and the limit; exit 5, as any stream over the limits)."""

    exit_code = EXIT_GOUGE


def _limits(machine: Machine, derate=(1.0, 1.0, 1.0)):
    """V, A, J used by the plan: MARGIN (times ``derate``) of each, the acceleration at
    most sqrt(V J)."""
    V = MARGIN * derate[0] * np.asarray(machine.max_velocity)
    J = MARGIN * derate[2] * np.asarray(machine.max_jerk)
    A = np.minimum(MARGIN * derate[1] * np.asarray(machine.max_acceleration), np.sqrt(V * J))
    return V, A, J


def _speed_limits(run: Run, V, J, period: float, d_share: float = D_SHARE) -> np.ndarray:
    """(n,) the squared speed limit at each grid point (before erosion), the jerk's
    D v³ term within ``d_share`` of J."""
    return plan_once.speed_limits(run.cap, run.T, run.D, run.jump, V, J, period, d_share,
                                  JOIN_SHARE)


def _d_binds(run: Run, V, J, period: float) -> bool:
    """Whether the D v³ term at D_SHARE lowers the run's speed limit anywhere."""
    return bool(np.any(_speed_limits(run, V, J, period)
                       < _speed_limits(run, V, J, period, math.inf)))


def _plan_once(run: Run, wl: np.ndarray, V, A, J, period: float, window: float,
               coriolis: float, reach=None, tight: bool = False):
    """One plan of the run with averaging ``window`` and the Coriolis term's share
    ``coriolis`` of J, the path's derivatives taken over ``reach`` ((lo, hi) (n,) arc
    lengths around each point; None: +- the top speed times the window; ``tight``: at
    each point only, and ``wl`` not held over the reach): t, w, u, v, a, S and per knot
    the window needed (:func:`.plan_once.plan_once`)."""
    if tight:
        return plan_once.plan_once(run.s, wl, run.T, run.K, run.D, run.jump, run.kink, A,
                                   J, period, window, coriolis, run.s, run.s, True, False)
    lo, hi = (run.s, run.s) if reach is None else reach
    return plan_once.plan_once(run.s, wl, run.T, run.K, run.D, run.jump, run.kink, A, J,
                               period, window, coriolis, lo, hi, reach is not None)


def _tightened(run: Run, wl, limits, period: float, window: float, coriolis: float, first):
    """The plan again with the derivatives taken only where the averaged motion goes
    (the first plan assumed the top speed everywhere); kept if its own ranges lie within
    the ranges it assumed and its window suffices, else ``first`` (sound as it is)."""
    V, A, J = limits
    s = run.s
    lo, hi = topp.ranges(first[0], s, first[3], first[4], first[5], window)
    for _ in range(TIGHTEN_ROUNDS):
        grow = TIGHTEN_SLACK * (hi - lo)
        assumed = (lo - grow, hi + grow)
        plan = _plan_once(run, wl, V, A, J, period, window, coriolis, assumed)
        if float(np.max(plan[6], initial=0.0)) > window:
            return first
        lo2, hi2 = topp.ranges(plan[0], s, plan[3], plan[4], plan[5], window)
        if (lo2 >= assumed[0]).all() and (hi2 <= assumed[1]).all():
            return plan
        lo, hi = np.minimum(lo, lo2), np.maximum(hi, hi2)
    return first


class _Loose(Exception):
    """A plan whose speed limits were not held over the window's reach (``tight``) and
    whose averaged motion, measured, goes over a velocity or acceleration limit."""


def _measured_window(run: Run, machine: Machine, limits, coriolis: float, cap: float,
                     d_share: float, window: float, beat: float) -> _Windowed:
    """A bending run's ``tight`` plan: the axes' velocity and D v³ speed limits where they
    are and its path's derivatives at each point (no reach); the limits that hold at a
    point (the programmed speed, a join's or a curvature jump's jolt) still held over the
    window's reach. The averaged motion's velocity, acceleration and jerk are all
    measured (:func:`.averaged_jerk.shares`). Where the velocity or acceleration goes
    over, the speed limits (squared) and the accelerations are scaled down by the share
    measured (a little more: SCALE_OVER), at most SCALE_ROUNDS times (then _Loose); where
    the jerk does, the window grows as in :func:`_windowed`."""
    V, A, J = limits
    period, n = machine.period, len(run.s)
    smooth = np.minimum(plan_once.speed_limits(
        np.full(n, np.inf), run.T, run.D, np.zeros_like(run.jump), V, J, period, d_share,
        JOIN_SHARE), cap * cap)
    points = plan_once.speed_limits(run.cap, run.T, np.zeros_like(run.D), run.jump,
                                    np.full(3, np.inf), J, period, d_share, JOIN_SHARE)
    kv = ka = 1.0
    grown, scaled, floor = None, 0, 0.0
    for _ in range(WINDOW_ROUNDS):
        # the window only grows and the limits only fall: the last raw profile's time
        # and this window already bound the plan's duration
        if floor + window >= beat:
            raise _Slower
        wl = np.minimum(smooth, reach.erode(run.s, points, window)) * kv
        plan = _plan_once(run, wl, V, A * ka, J, period, window, coriolis, tight=True)
        t, w, u, v, a, S, need = plan
        _moves(run, t)
        floor = float(t[-1])
        if floor + window >= beat:
            raise _Slower
        sv, sa, sj = averaged_jerk.shares(t, run.s, v, a, S, window, run.s, run.T, run.K,
                                          run.D, run.jump, run.kink, V, A, J,
                                          machine.period, run.cap)
        if not math.isfinite(sj):
            raise PlanError(f"pieces {run.first + 1}..{run.first + len(run.pieces)}: the "
                            "curvature leaves no jerk for the feed to change")
        if sj > 1.0:   # the window first, as in _windowed
            step = _secant(grown, window, sj)
            grown = (window, sj)
            window = window * max(sj, WINDOW_GROWTH) if step is None else step
            continue
        if sv <= 1.0 and sa <= 1.0:
            return _Windowed(coriolis, window, wl, plan, True)
        scaled += 1
        if scaled > SCALE_ROUNDS:
            raise _Loose
        kv /= max(sv, 1.0) ** 2 * (1.0 + SCALE_OVER)
        ka /= max(sa, 1.0) * (1.0 + SCALE_OVER)
        grown = None   # the jerk's secant was of other limits
    raise PlanError(f"pieces {run.first + 1}..{run.first + len(run.pieces)}: no "
                    f"averaging window keeps the jerk within {machine.summary()}")


def _measured(run: Run, plan: tuple, window: float, J, period: float) -> float:
    """The largest share of J that the plan averaged over ``window`` takes, measured on the
    averaged motion itself (:func:`.averaged_jerk.peak_share`) on a run that bends (inf
    on one that does not: there the curvature terms leave :func:`.topp.window_needed`
    nothing to overestimate)."""
    if not run.bends:
        return math.inf
    t, w, u, v, a, S, need = plan
    return averaged_jerk.peak_share(t, run.s, v, a, S, window, run.s, run.T, run.K, run.D,
                                    run.jump, run.kink, J, period)


def _grew(run: Run, limits, plan: _Windowed) -> bool:
    """Whether the plan's window is longer than the first one (beyond round-off)."""
    return plan.window > _first_window(run, limits[1], limits[2]) * (1.0 + 1e-9)  # round-off


def _first_window(run: Run, A, J) -> float:
    """The first averaging window (s): the shortest A_i / J_i of the axes the run moves;
    the plan lengthens it where the profile needs more."""
    t = run.tangent_reach
    return float(np.min(np.where(t > 0.0, A / J, np.inf)))


@dataclass
class _Windowed:
    """A run's plan at one Coriolis share once its window suffices, before the derivatives
    are tightened: ``plan`` as :func:`.plan_once.plan_once` returns it."""

    coriolis: float
    window: float
    wl: np.ndarray
    plan: tuple
    measured: bool = False   # its limits where they are (:func:`_measured_window`)

    @property
    def duration(self) -> float:
        return float(self.plan[0][-1]) + self.window


def _windowed(run: Run, machine: Machine, limits, coriolis: float,
              cap: float = math.inf, d_share: float = D_SHARE,
              beat: float = math.inf, tight: bool = False) -> _Windowed:
    """The run's plan with the Coriolis term's share ``coriolis`` and the D v³ term's
    ``d_share`` of J (see the module doc), its speed at most ``cap`` (mm/s): turns
    flattened, or the window grown, until the window is long enough. _Slower as soon as
    a round lasts ``beat`` s or more. ``tight``: the measured plan instead
    (:func:`_measured_window`)."""
    V, A, J = limits
    window = _first_window(run, A, J)
    if tight:
        return _measured_window(run, machine, limits, coriolis, cap, d_share, window, beat)
    wl = np.minimum(_speed_limits(run, V, J, machine.period, d_share), cap * cap)
    flattening, last = True, math.inf
    grown = None   # (window, measured) of the last window grown from
    for round_ in range(WINDOW_ROUNDS):
        plan = _plan_once(run, wl, V, A, J, machine.period, window, coriolis)
        t, w, u, v, a, S, need = plan
        _moves(run, t)
        if float(t[-1]) + window >= beat:
            raise _Slower
        top = float(np.max(need, initial=0.0))
        if top <= window * (1.0 + NEED_ROUNDOFF):
            return _Windowed(coriolis, window, wl, plan)
        flattening = flattening and round_ < FLATTEN_ROUNDS and \
            top < last * (1.0 - NEED_ROUNDOFF)   # progress beyond round-off
        last = top
        # the motion measured as it comes, and once the flattening stops: not between
        early = round_ == 0 or not flattening
        measured = _measured(run, plan, window, J, machine.period) if early else math.inf
        if measured <= 1.0:
            return _Windowed(coriolis, window, wl, plan)
        if flattening and topp.flatten(run.s, t, w, u, wl, need, window):
            continue
        if not early:   # nothing left to flatten: measured now
            measured = _measured(run, plan, window, J, machine.period)
            if measured <= 1.0:
                return _Windowed(coriolis, window, wl, plan)
        if not math.isfinite(top):
            raise PlanError(f"pieces {run.first + 1}..{run.first + len(run.pieces)}: the "
                            "curvature leaves no jerk for the feed to change (limits "
                            f"{machine.summary()})")
        # where the motion is measured (a run that bends), the window grows as much as the
        # measured jerk asks (the tangential part goes as 1 / window), the bound at most
        if not math.isfinite(measured):
            window = top
            continue
        step = _secant(grown, window, measured)
        grown = (window, measured)
        window = min(top, window * max(measured, WINDOW_GROWTH) if step is None else step)
    raise PlanError(f"pieces {run.first + 1}..{run.first + len(run.pieces)}: no "
                    f"averaging window keeps the jerk within {machine.summary()}")


def _moves(run: Run, t: np.ndarray) -> None:
    """PlanError where the plan's time is not finite: a speed limit of 0 inside the run,
    or a grid with no knot to accelerate on and another to brake on."""
    if not math.isfinite(float(t[-1])):
        raise PlanError(f"pieces {run.first + 1}..{run.first + len(run.pieces)}: the speed "
                        "limits leave no motion from rest to rest")


def _secant(before, window: float, measured: float) -> float | None:
    """The window at which the measured share would reach 1, taking it as c + d / W
    through the last two windows measured (the tangential part goes as 1 / W, the
    curvature terms stay), a little beyond; None without two such windows or where the
    line does not reach 1 beyond ``window``."""
    if before is None or not before[0] < window or not before[1] > measured:
        return None
    d = (before[1] - measured) / (1.0 / before[0] - 1.0 / window)
    c = measured - d / window
    if not (d > 0.0 and c < 1.0):
        return None
    return max(d / (1.0 - c) * SECANT_OVER, window * SECANT_GROWTH)


def _profile(run: Run, machine: Machine, limits, chosen: _Windowed) -> Profile:
    """The chosen plan with, on a curved run, the derivatives taken only where the motion
    goes (a straight run's are the same everywhere), as a profile."""
    plan = chosen.plan
    if run.curved and not run.bends:   # a bending run's jerk is measured as it is
        plan = _tightened(run, chosen.wl, limits, machine.period, chosen.window,
                          chosen.coriolis, plan)
    t, w, u, v, a, S, need = plan
    keep = np.append(run.s[1:] > run.s[:-1], True)
    return Profile(t[keep], run.s[keep], v[keep], a[keep], S[keep], chosen.window,
                   chosen.measured)


def plan_run(run: Run, machine: Machine, derate=(1.0, 1.0, 1.0),
             measured: bool = True) -> Profile:
    """The jerk-limited, near time-optimal profile of one run (see the module doc);
    ``derate`` (3,) scales the velocity, acceleration and jerk used; ``measured`` False:
    no measured plan (step 6)."""
    V, A, J = _limits(machine, derate)
    # a short run: the acceleration a jerk ramp up and down over its length reaches
    A = np.minimum(A, np.cbrt(J * J * run.length))
    even = _even_ratio(run, A, J)
    tries = [(A, D_SHARE)] + ([] if even is None else [(even, D_SHARE)])
    if _d_binds(run, V, J, machine.period):
        high = [(A, D_SHARE_HIGH)] + ([] if even is None else [(even, D_SHARE_HIGH)])
        # a bending run whose D v³ term binds is mostly fastest at the higher share: planned
        # first, it lets the others give up early (their rounds only get longer)
        tries = high + tries if run.bends else tries + high
    plan = None
    for acceleration, d_share in tries:
        # a run that bends is not tightened after: its rounds bound the profile's duration
        beat = plan.duration if run.bends and plan is not None else math.inf
        try:
            other = _best_share(run, machine, (V, acceleration, J), d_share, beat)
        except PlanError:   # no jerk left for the feed to change at that share
            if d_share == D_SHARE and acceleration is A:
                raise
            continue
        if plan is None or other.duration < plan.duration * (1.0 - TIE):   # a tie: the first
            plan, won = other, (acceleration, d_share)
    if measured and run.bends:   # the winner's limits where they are, the motion measured
        limits = (V, won[0], J)
        try:
            chosen = _capped(run, machine, limits, won[1], plan.duration, tight=True)
        except (PlanError, _Slower, _Loose):
            return plan
        if chosen.duration < plan.duration * (1.0 - TIE):
            plan = _profile(run, machine, limits, chosen)
    return plan


def _best_share(run: Run, machine: Machine, limits, d_share: float = D_SHARE,
                beat: float = math.inf) -> Profile:
    """The run planned at CORIOLIS_SHARE; where the curvature terms lengthened its window
    past the first one, the share moved by SHARE_STEP while that shortens the run (a larger
    share lets the feed change faster on a curve but asks for a longer window). The shares
    are compared before the derivatives are tightened, and only the chosen one is. A run
    that bends is planned by :func:`_capped` instead (its jerk measured), this way only
    where no window serves BENT_SHARE. ``beat`` (a run that bends only: the others'
    durations fall when tightened): what :func:`_capped`'s capped plans are to beat; the
    search's first share is planned in full (a later share may be faster), each next
    share gives up once it can no longer beat the last."""
    if run.bends:
        try:
            return _profile(run, machine, limits,
                            _capped(run, machine, limits, d_share, beat))
        except PlanError:   # no window for that share: the usual one
            pass
    first = _windowed(run, machine, limits, CORIOLIS_SHARE, d_share=d_share)
    if not _grew(run, limits, first):
        return _profile(run, machine, limits, first)
    for step, steps in ((-SHARE_STEP, SHARE_STEPS), (SHARE_STEP, SHARE_STEPS)):
        best, share = first, CORIOLIS_SHARE
        for _ in range(steps):
            share += step
            try:
                other = _windowed(run, machine, limits, share, d_share=d_share,
                                  beat=best.duration)
            except (PlanError, _Slower):   # no window for that share, or no faster: the
                break                      # search ends there
            if other.duration >= best.duration:
                break
            best = other
        if best is not first:
            return _profile(run, machine, limits, best)
    return _profile(run, machine, limits, first)


def _capped(run: Run, machine: Machine, limits, d_share: float = D_SHARE,
            beat: float = math.inf, tight: bool = False) -> _Windowed:
    """A bending run at BENT_SHARE (less where the D v³ share leaves less: BENT_ROOM);
    where its window had to grow, also with its top speed capped at each of CAP_FACTORS
    of the plan's (a slower top asks for less window), the fastest kept: a looser limit
    that lets the feed higher never lengthens the run more than these caps can give back.
    Only the capped plans give up early (against ``beat`` and the uncapped plan): the
    uncapped one is planned in full, as the caps are shares of its top speed. ``tight``:
    measured plans (:func:`_measured_window`), which no later plan depends on, the
    uncapped one too giving up against ``beat``."""
    bent = min(BENT_SHARE, 1.0 - d_share - BENT_ROOM)
    best = _windowed(run, machine, limits, bent, d_share=d_share,
                     beat=beat if tight else math.inf, tight=tight)
    if not _grew(run, limits, best):
        return best
    top = float(np.max(best.plan[3]))
    for factor in CAP_FACTORS:
        try:
            other = _windowed(run, machine, limits, bent, factor * top, d_share,
                              min(beat, best.duration), tight)
        except (PlanError, _Slower, _Loose):
            continue
        if other.duration < best.duration:
            best = other
    return best


def _even_ratio(run: Run, A: np.ndarray, J: np.ndarray) -> np.ndarray | None:
    """(3,) the accelerations with no moving axis asking for a longer jerk ramp than the
    quickest one (A_i <= J_i min_k A_k / J_k), or None where they already do. The window
    serves every axis at once, so an axis with more acceleration than that lengthens it:
    planned both ways, the faster kept, a looser acceleration limit never slows a run."""
    moving = run.tangent_reach > 0.0
    if not moving.any():
        return None
    even = np.minimum(A, J * float(np.min((A / J)[moving])))
    return None if np.array_equal(even[moving], A[moving]) else even
