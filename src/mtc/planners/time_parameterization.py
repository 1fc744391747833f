"""Time parameterization: times, velocities and accelerations for a geometric path.

:class:`TimeOptimalTrajectoryGeneration` (the name of MoveIt's TOTG, MTC's default
``time_parameterization``) assigns times to the waypoints of a :class:`RobotTrajectory` so that
the path is traversed as fast as the joint velocity and acceleration limits allow, scaled by
``max_velocity_scaling_factor`` and ``max_acceleration_scaling_factor``. The waypoints are kept
(MoveIt's TOTG resamples them; MTC's planners and cost terms only need the times).

How: the waypoints are joined by a monotone piecewise cubic Hermite interpolant ``q(s)``
(three-point tangents held to de Boor and Swartz's monotonicity bound) in the joint-space arc
length ``s``: the path has a
continuous tangent ``q'(s)``, stays on straight lines between collinear waypoints, and between
two waypoints no joint leaves the range of its two values (a joint that stands still has zero
velocity; nothing overshoots a bound the waypoints touch). Along the path, ``q̇ = q' ṡ`` and
``q̈ = q' s̈ + q'' ṡ²``, so with ``x = ṡ²`` and ``u = s̈`` every joint limit is linear in
``(u, x)``. On a grid in ``s`` that contains every waypoint, a backward pass computes the largest
``x`` from which the path can still end at rest (the controllable set) and a forward pass then
takes the largest admissible ``u`` at each grid point (the reachability analysis of TOPP-RA,
Pham & Pham 2018). Each grid interval is held to the acceleration limits at its ends and its
middle (the curvature jumps at waypoints), and to the velocity limits at its middle through
the speeds at both of its ends. Taking the largest ``u`` is optimal where a faster point never
leaves the next one less room; where it would (an acceleration bound that tightens quickly
with the speed, on a grid coarse for the path's curvature), a point's speed is held to where
the next point keeps at least half of the most it could reach, so the motion never comes to a
stop that the path does not call for. By construction, every reported velocity and
acceleration lies within the scaled limits. Waypoints that lie in order
on one straight segment (joint interpolation, a gripper's motion) are timed in closed form:
the optimum there is the trapezoid of the path coordinate that the passes converge to.

A Cartesian speed limit on a link (MTC's ``max_cartesian_speed`` for
``cartesian_speed_limited_link``) is one more velocity constraint ``‖p'(s)‖ ṡ ≤ v_max`` on
the interpolant of the link's positions.

Ruckig (the only ruckig user in ``mtc`` is this module) does state-to-state motions: it
cannot follow a given path, so it serves :class:`TrapezoidProfile` (one coordinate rest to
rest, for Pilz's LIN and CIRC) and :func:`synchronized_ptp` (Pilz's PTP: all joints start and
stop together on the straight joint-space line).
"""

from __future__ import annotations

import logging
import math
from abc import ABC, abstractmethod

import numpy as np
import ruckig

from mtc import msgs
from mtc.scene.robot_trajectory import RobotTrajectory

log = logging.getLogger(__name__)

__all__ = [
    "TimeParameterization",
    "TimeOptimalTrajectoryGeneration",
    "time_parameterize",
    "limit_cartesian_speed",
    "slow_to_cartesian_speed",
    "synchronized_ptp",
    "TrapezoidProfile",
    "check_scaling_factor",
]

_EPS_TANGENT = 1e-9  # a joint whose path tangent is smaller than this does not limit ṡ
_REPEATED = 1e-12  # a waypoint closer than this to the one before it repeats it [rad, m]
_MIN_PARTS = 2  # grid intervals per waypoint interval, at least
_NEXT_SHARE = 0.5  # a grid point's speed leaves the next one at least this share of its best (see _time_optimal)
_STRAIGHT = 1e-9  # off a line by this fraction of the step to the next waypoint: on it (see _straight_line)
#: Scaling factors below this are timed on a faster copy of the limits (see time_parameterize):
#: the passes work with squared path speeds, which underflow to 0 below about 1e-154.
_TINY_SCALING = 1e-100
#: The smallest scaling factor accepted (besides 0, the default): a motion still slower could
#: last longer than a float can say.
MIN_SCALING_FACTOR = 1e-300
#: A trapezoid profile expected to last longer than this [s] (ruckig refuses about 1e10 s) is
#: computed on a faster time scale (see TrapezoidProfile).
_LONG_PROFILE = 1e9


def check_scaling_factor(name: str, value: float) -> float:
    """Validate a velocity/acceleration scaling factor; 0 means the default, 1.0 (as MoveIt's
    time parameterization takes it).

    Raises:
        ValueError: not a number in [0, 1], or below :data:`MIN_SCALING_FACTOR` (but not 0).
    """
    if not msgs.is_number(value):
        raise ValueError(f"{name} must be a number in (0, 1] (0: the default, 1.0), got {value!r}")
    v = float(value)
    if not (0.0 <= v <= 1.0):
        raise ValueError(f"{name} must be in (0, 1] (0: the default, 1.0), got {value!r}")
    if 0.0 < v < MIN_SCALING_FACTOR:
        raise ValueError(f"{name} must be in (0, 1] and not below {MIN_SCALING_FACTOR:g} "
                         f"(a motion that slow could last longer than a float holds), got {value!r}")
    return v if v > 0.0 else 1.0


class TimeParameterization(ABC):
    """A way to time a geometric trajectory (MoveIt's ``TimeParameterization``)."""

    @abstractmethod
    def computeTimeStamps(
        self,
        trajectory: RobotTrajectory,
        max_velocity_scaling_factor: float = 1.0,
        max_acceleration_scaling_factor: float = 1.0,
    ) -> bool:
        """Set the trajectory's times, velocities and accelerations in place.

        Returns:
            Whether the trajectory could be timed.
        """


class TimeOptimalTrajectoryGeneration(TimeParameterization):
    """Time-optimal timing along the path under joint velocity and acceleration limits.

    Args:
        grid_points: minimum number of grid intervals along the path (more: closer to the
            continuous optimum, slower). Every waypoint is a grid point.
    """

    def __init__(self, grid_points: int = 100):
        if int(grid_points) < 1:
            raise ValueError(f"grid_points must be at least 1, got {grid_points}")
        self.grid_points = int(grid_points)

    def computeTimeStamps(
        self,
        trajectory: RobotTrajectory,
        max_velocity_scaling_factor: float = 1.0,
        max_acceleration_scaling_factor: float = 1.0,
    ) -> bool:
        time_parameterize(
            trajectory, max_velocity_scaling_factor, max_acceleration_scaling_factor, grid_points=self.grid_points
        )
        return True

    def __repr__(self) -> str:
        return f"TimeOptimalTrajectoryGeneration(grid_points={self.grid_points})"


# ---------------------------------------------------------------------------------------------
# shape-preserving cubic through the waypoints, parameterized by arc length


def _monotone_slopes(s: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """Tangents at the knots of a monotone piecewise cubic Hermite interpolant through
    ``(s, Y)`` (columns of Y are independent curves): a coordinate that
    turns or stands still at a knot gets a zero tangent there, so between two knots each
    coordinate stays between its two values (no overshoot past a waypoint, a bound or a
    stationary joint's value), and collinear waypoints give the straight line."""
    n = len(s)
    h = np.diff(s)[:, None]
    delta = np.diff(Y, axis=0) / h
    if n == 2:
        return np.repeat(delta, 2, axis=0)
    M = np.zeros_like(Y)
    # interior: the three-point (Bessel) tangent, second-order accurate on smooth paths, held
    # to zero where the neighbouring slopes disagree in sign and to 3x the smaller slope
    # (de Boor and Swartz's bound: each piece then stays monotone)
    h0, h1 = h[:-1], h[1:]
    d0, d1 = delta[:-1], delta[1:]
    m = (h1 * d0 + h0 * d1) / (h0 + h1)
    bound = 3.0 * np.minimum(np.abs(d0), np.abs(d1))
    M[1:-1] = np.where(d0 * d1 > 0.0, np.sign(m) * np.minimum(np.abs(m), bound), 0.0)
    # ends: the three-point estimate, kept to the first (last) slope's sign and to 3x its size
    for end, (ha, hb, da, db) in ((0, (h[0], h[1], delta[0], delta[1])), (-1, (h[-1], h[-2], delta[-1], delta[-2]))):
        m = ((2.0 * ha + hb) * da - ha * db) / (ha + hb)
        m = np.where(np.sign(m) != np.sign(da), 0.0, m)
        m = np.where((np.sign(da) != np.sign(db)) & (np.abs(m) > 3.0 * np.abs(da)), 3.0 * da, m)
        M[end] = m
    return M


def _hermite_derivatives(s, Y, M, seg, t):
    """First and second derivatives of the Hermite cubic at points ``t`` lying in segments ``seg``."""
    h = (s[seg + 1] - s[seg])[:, None]
    u = (t[:, None] - s[seg][:, None]) / h
    y0, y1, m0, m1 = Y[seg], Y[seg + 1], M[seg] * h, M[seg + 1] * h
    d1 = ((6 * u * u - 6 * u) * (y0 - y1) + (3 * u * u - 4 * u + 1) * m0 + (3 * u * u - 2 * u) * m1) / h
    d2 = ((12 * u - 6) * (y0 - y1) + (6 * u - 4) * m0 + (6 * u - 2) * m1) / (h * h)
    return d1, d2


def _straight_line(Q, vmax, amax):
    """Times, velocities and accelerations for waypoints that lie in order on one straight
    joint-space segment (joint interpolation, a gripper opening), or None for any other path.

    The time-optimal motion along a straight line is the rest-to-rest trapezoid (or triangle)
    of the path coordinate with the largest speed and acceleration every joint allows, the
    limit the grid passes of :func:`_time_optimal` converge to; in closed form it takes
    microseconds where the passes take about a millisecond."""
    d = Q[-1] - Q[0]
    length = math.sqrt(float(d @ d))
    if length <= _REPEATED:
        return None
    u = d / length
    s = (Q - Q[0]) @ u
    steps = np.diff(s)
    if not np.all(steps > 0.0):
        return None
    # every waypoint on the line to within a tiny fraction of its distance to its neighbours:
    # a sideways step, however small, between two close waypoints is a corner the passes time
    off = np.abs(Q - Q[0] - s[:, None] * u).max(axis=1)
    near = np.minimum(np.append(steps, np.inf), np.insert(steps, 0, np.inf))
    if np.any(off > _STRAIGHT * near):
        return None
    au = np.abs(u)
    moving = au > _EPS_TANGENT
    sv = float(np.min(vmax[moving] / au[moving]))
    sa = float(np.min(amax[moving] / au[moving]))
    if not (sv > 0.0 and sa > 0.0):  # a moving joint without a limit to move by: the passes decide
        return None
    s[-1] = length  # exactly: the time to rest grows with the square root of what is left
    ramp = min(0.5 * sv * sv / sa, 0.5 * length)  # path length of the speed-up (and slow-down)
    # (where the ramp underflows, from tiny scaling factors: the same peak, without it)
    peak = math.sqrt(2.0 * sa * ramp) if ramp > 1e-250 else min(sv, math.sqrt(sa * length))
    t_ramp = peak / sa
    rest = length - s
    up, down = s < ramp, s >= length - ramp
    speed = np.where(up, np.sqrt(2.0 * sa * s), np.where(down, np.sqrt(2.0 * sa * rest), peak))
    times = np.where(
        up,
        speed / sa,
        np.where(down, 2.0 * t_ramp + (length - 2.0 * ramp) / peak - speed / sa, t_ramp + (s - ramp) / peak),
    )
    accel = np.where(up, sa, np.where(down, -sa, 0.0))
    accel[-1] = -sa  # at rest at the end, still braking (as the passes report it)
    return times, speed[:, None] * u, accel[:, None] * u


# ---------------------------------------------------------------------------------------------
# the phase-plane passes


def _time_optimal(Q, vmax, amax, grid_points, P=None, vcart=0.0, PJ=None):
    """Times, velocities and accelerations for the path through the rows of ``Q``.

    Args:
        Q: N x k waypoints (continuous joints already unwrapped; no row repeats the one before
            it, see :data:`_REPEATED`).
        vmax, amax: k scaled limits.
        grid_points: minimum number of grid intervals.
        P: optional N x 3 positions of a link whose speed is limited to ``vcart``.
        PJ: optional N x 3 x k Jacobians of those positions: the link's path then has the
            tangents the joints' path gives it at the waypoints (else its own estimate).
    """
    N, k = Q.shape
    times = np.zeros(N)
    V = np.zeros((N, k))
    A = np.zeros((N, k))
    if N < 2:
        return times, V, A
    n = N  # (the knots are the waypoints)
    s = np.concatenate(([0.0], np.cumsum(np.sqrt((np.diff(Q, axis=0) ** 2).sum(axis=1)))))
    L = s[-1]
    Y = Q if P is None else np.hstack((Q, P))
    M = _monotone_slopes(s, Y)
    if PJ is not None:
        M[:, k:] = np.einsum("nij,nj->ni", PJ, M[:, :k])

    # grid: each knot interval split into equal parts, about grid_points parts in total and at
    # least two per interval (the curvature of an interval next to a corner changes fast)
    h = np.diff(s)
    parts = np.maximum(_MIN_PARTS, np.ceil(h * (grid_points / L) - 1e-9)).astype(int)
    seg = np.repeat(np.arange(n - 1), parts)
    starts = np.repeat(np.cumsum(parts) - parts, parts)
    frac = (np.arange(parts.sum()) - starts) / np.repeat(parts, parts)
    grid = np.concatenate((s[seg] + frac * h[seg], [L]))
    seg = np.concatenate((seg, [n - 2]))
    knot_index = np.concatenate(([0], np.cumsum(parts)))
    d1, d2 = _hermite_derivatives(s, Y, M, seg, grid)
    qp, qpp = d1[:, :k], d2[:, :k]
    G = len(grid)
    # the curvature jumps at the knots: each grid interval is held to the acceleration limits at
    # its start, its middle and its end, as its own cubic has them. With u constant over the
    # interval, x = ṡ² grows linearly in s: x_i + 2 f Δ u at the fraction f of it, so q' u + q'' x
    # there is linear in (u, x_i) too: coefficient q' + 2 f Δ q'' on u and q'' on x_i.
    cols_p, cols_pp = [qp], [qpp]
    delta = np.diff(grid)[:, None]
    mid = None
    for f in (0.5, 1.0):
        f1, f2 = _hermite_derivatives(s, Y, M, seg[:-1], grid[:-1] + f * delta[:, 0])
        mid = f1 if mid is None else mid
        cols_p.append(np.vstack((f1[:, :k] + 2.0 * f * delta * f2[:, :k], qp[-1:])))
        cols_pp.append(np.vstack((f2[:, :k], qpp[-1:])))
    cp, cpp = np.hstack(cols_p), np.hstack(cols_pp)
    amax = np.tile(amax, len(cols_p))

    # constraints per grid point: velocity bound on x, and u in [max(-c + b x), min(c + b x)]
    aq = np.abs(cp)
    active = aq > _EPS_TANGENT
    safe = np.where(active, aq, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        vq = np.abs(qp)
        xmax = np.min(np.where(vq > _EPS_TANGENT, (vmax / np.where(vq > _EPS_TANGENT, vq, 1.0)) ** 2, np.inf), axis=1)
        c = np.where(active, amax / safe, np.inf)
        beta = np.where(active, -cpp / np.where(active, cp, 1.0), 0.0)
        # constraints whose u coefficient vanishes: |q''| x <= a
        curv = np.abs(cpp)
        xmax = np.minimum(xmax, np.min(np.where(~active & (curv > 1e-12), amax / np.where(curv > 0, curv, 1.0), np.inf), axis=1))
        # the u-interval is empty above min over pairs with beta_i > beta_j of (c_i + c_j) / (beta_i - beta_j)
        # (pairs with beta_i <= beta_j divide by 0: inf, as c > 0)
        db = beta[:, :, None] - beta[:, None, :]
        np.maximum(db, 0.0, out=db)
        pair = c[:, :, None] + c[:, None, :]
        np.divide(pair, db, out=pair)
        xmax = np.minimum(xmax, pair.reshape(G, -1).min(axis=1))
        if P is not None:
            pp = d1[:, k:]  # (the link's position is C1: its speed bound at the grid points)
            speed2 = (pp**2).sum(axis=1)
            xmax = np.minimum(xmax, np.where(speed2 > 1e-18, vcart * vcart / np.where(speed2 > 0, speed2, 1.0), np.inf))
        # speeds at the middle of each interval: there x = (x_i + x_{i+1}) / 2, and (q'_m)² x <= v²
        # for every joint (and the link) holds where both ends stay below W, the least of
        # v² / (q'_m)². (The midpoint bound itself, x_i + x_{i+1} <= 2 W, would couple the ends:
        # the larger x_i, the smaller the largest x_{i+1}, and the forward pass, which takes
        # each x as large as it can, could then be forced to a stop at the next point.)
        mq = np.abs(mid[:, :k])
        W = np.min(np.where(mq > _EPS_TANGENT, (vmax / np.where(mq > _EPS_TANGENT, mq, 1.0)) ** 2, np.inf), axis=1)
        if P is not None:
            speed2 = (mid[:, k:] ** 2).sum(axis=1)
            W = np.minimum(W, np.where(speed2 > 1e-18, vcart * vcart / np.where(speed2 > 0, speed2, 1.0), np.inf))
        xmax[:-1] = np.minimum(xmax[:-1], W)
        xmax[1:] = np.minimum(xmax[1:], W)
    if not np.all(np.isfinite(xmax)):
        # a point where nothing limits the speed (the path does not move any joint): cannot be
        xmax = np.where(np.isfinite(xmax), xmax, 0.0)

    dsa = np.diff(grid)
    ds = dsa.tolist()
    c_fin = np.where(np.isfinite(c), c, 1e300)
    c_rows = c_fin.tolist()
    b_rows = beta.tolist()
    # backward-pass lines: x_i <= (x_{i+1} + 2Δ c) / (1 + 2Δ b) = A + B x_{i+1} where 1 + 2Δ b > 0
    two_d = 2.0 * dsa[:, None]
    slope = 1.0 + two_d * beta[:-1]
    binding = (slope > 0.0) & np.isfinite(c[:-1])
    safe_slope = np.where(binding, slope, 1.0)
    A_rows = np.where(binding, two_d * c_fin[:-1] / safe_slope, np.inf).tolist()
    B_rows = np.where(binding, 1.0 / safe_slope, 0.0).tolist()
    # where 1 + 2Δ b < 0, the largest u (c + b x) still leaves x_{i+1} = x_i + 2Δ u >= 0 only for
    # x_i <= 2Δ c / -(1 + 2Δ b): above it the interval cannot be crossed without stopping
    falling = (slope < 0.0) & np.isfinite(c[:-1])
    crossable = np.where(falling, two_d * c_fin[:-1] / np.where(falling, -slope, 1.0), np.inf).min(axis=1)
    # the largest x_{i+1} reachable from x_i, the least of the lines x_i (1 + 2Δ b) + 2Δ c, falls
    # as x_i rises once a falling line (1 + 2Δ b < 0) is the least one. There the forward pass,
    # which takes each x as large as it can, could leave the next point slow or even stopped:
    # x_i is held to where the next point keeps _NEXT_SHARE of the most it can reach (that most
    # at xs, where the least rising line meets the least falling one; the share at xr beyond)
    hold = np.full(G - 1, np.inf)
    rows = np.nonzero(falling.any(axis=1))[0]
    if rows.size:
        a = two_d[rows] * c_fin[:-1][rows]
        b = slope[rows]
        finite = np.isfinite(c[:-1][rows])
        rising, fall = finite & (b >= 0.0), finite & (b < 0.0)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            # where rising line p and falling line q cross (p below q before, above after)
            cross = (a[:, None, :] - a[:, :, None]) / (b[:, :, None] - b[:, None, :])
        cross = np.where(rising[:, :, None] & fall[:, None, :], cross, -np.inf)
        xs = np.maximum(np.where(fall, cross.max(axis=1), np.inf).min(axis=1), 0.0)
        top = np.where(finite, a + b * xs[:, None], np.inf).min(axis=1)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            xr = np.where(fall, (_NEXT_SHARE * top[:, None] - a) / np.where(fall, b, -1.0), np.inf).min(axis=1)
        hold[rows] = np.maximum(xs, xr)
    crossable = np.minimum(crossable, hold)
    xm = np.minimum(xmax, np.concatenate((crossable, [np.inf]))).tolist()

    # backward pass: largest x at each grid point from which the end (at rest) is reachable
    xb = [0.0] * G
    for i in range(G - 2, -1, -1):
        bound = xm[i]
        nxt = xb[i + 1]
        for a, b in zip(A_rows[i], B_rows[i]):
            v = a + b * nxt
            if v < bound:
                bound = v
        xb[i] = bound if bound > 0.0 else 0.0

    # forward pass: from rest, the largest admissible acceleration that stays controllable
    x = [0.0] * G
    u = [0.0] * G
    for i in range(G - 1):
        two_di = 2.0 * ds[i]
        xi = x[i]
        umax = (xb[i + 1] - xi) / two_di
        umin = -math.inf
        for ci, bi in zip(c_rows[i], b_rows[i]):
            bx = bi * xi
            if ci + bx < umax:
                umax = ci + bx
            if bx - ci > umin:
                umin = bx - ci
        ui = umax if umax > umin else umin  # umin <= umax holds up to rounding
        u[i] = ui
        xn = xi + two_di * ui
        x[i + 1] = min(max(xn, 0.0), xb[i + 1])
    # at the end (x = 0) keep the last deceleration, clamped into the last point's limits
    cl = min(c_rows[-1]) if c_rows[-1] else 0.0
    u[-1] = min(max(u[-2], -cl), cl)

    xa = np.array(x)
    ua = np.array(u)
    sq = np.sqrt(xa)
    denom = sq[:-1] + sq[1:]
    dt = np.where(denom > 0, 2.0 * np.diff(grid) / np.where(denom > 0, denom, 1.0), 0.0)
    tgrid = np.concatenate(([0.0], np.cumsum(dt)))
    vel = qp * sq[:, None]
    acc = qp * ua[:, None] + qpp * xa[:, None]
    return tgrid[knot_index], vel[knot_index], acc[knot_index]


def _link_positions(trajectory: RobotTrajectory, frame: str) -> tuple[np.ndarray, np.ndarray]:
    """Positions (N x 3) of a link or attached frame at the waypoints, and their Jacobians
    (N x 3 x k) with respect to the trajectory's group variables."""
    P, PJ = [], []
    for w in trajectory.waypoints:
        entry = w.get_attached_frame(frame)
        link, offset = entry if entry is not None else (frame, None)
        P.append(w.get_frame_transform(frame)[:3, 3])
        PJ.append(w.get_jacobian(trajectory.group, link, None if offset is None else offset[:3, 3])[:3])
    return np.array(P), np.array(PJ)


def time_parameterize(
    trajectory: RobotTrajectory,
    max_velocity_scaling_factor: float = 1.0,
    max_acceleration_scaling_factor: float = 1.0,
    max_cartesian_speed: float = 0.0,
    cartesian_speed_limited_link: str = "",
    grid_points: int = 100,
) -> RobotTrajectory:
    """Time a trajectory time-optimally along its path (in place), starting and ending at rest.

    Args:
        trajectory: the waypoints to time; their positions are kept.
        max_velocity_scaling_factor: fraction (0, 1] of the model's velocity limits.
        max_acceleration_scaling_factor: fraction (0, 1] of the acceleration limits.
        max_cartesian_speed: if > 0, the speed limit [m/s] of ``cartesian_speed_limited_link``.
        cartesian_speed_limited_link: a link (or attached frame) of the waypoints.
        grid_points: minimum number of grid intervals along the path.

    Returns:
        The trajectory, with times, velocities and accelerations set, and its continuous
        joints unwound (each step the short way round, as MoveIt's ``unwind()``); a waypoint
        that repeats the one before it is removed (as by MoveIt's TOTG), so times increase.

    Raises:
        ValueError: a scaling factor outside (0, 1], a negative Cartesian speed, or a Cartesian
            speed limit without a link.
        KeyError: unknown link.
    """
    # everything is checked before the trajectory changes
    vs = check_scaling_factor("max_velocity_scaling_factor", max_velocity_scaling_factor)
    acs = check_scaling_factor("max_acceleration_scaling_factor", max_acceleration_scaling_factor)
    if not msgs.is_number(max_cartesian_speed) or not max_cartesian_speed >= 0:
        raise ValueError(f"max_cartesian_speed must be a number >= 0 (0: no limit), got {max_cartesian_speed!r}")
    if not msgs.is_number(grid_points, integral=True) or grid_points < 1:
        raise ValueError(f"grid_points must be a whole number >= 1, got {grid_points!r}")
    model = trajectory.robot_model
    idx = trajectory.group.variable_indices
    # Time is stretched by k where a factor is tiny: a motion k times faster with its limits k
    # (velocities) and k^2 (accelerations) times higher keeps the passes' numbers in range;
    # an acceleration factor still above 1e100 is capped there (the speed-ups then take
    # 1e-100 of the time or less)
    k = math.exp(-0.5 * math.log(vs) - 0.25 * math.log(acs)) if min(vs, acs) < _TINY_SCALING else 1.0
    vmax = model.velocity_limits[idx] * (vs * k)
    amax = model.acceleration_limits[idx] * min(acs * k * k, 1e100)  # (acs itself where k is 1)
    if max_cartesian_speed > 0:
        if not cartesian_speed_limited_link:
            raise ValueError("max_cartesian_speed > 0 needs a cartesian_speed_limited_link")
        if len(trajectory):
            trajectory.waypoints[0].get_frame_transform(cartesian_speed_limited_link)  # KeyError: unknown
    bad = ~np.isfinite(trajectory.positions).all(axis=1)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(f"waypoint {i} has positions that are not finite numbers: {trajectory.positions[i].tolist()}")
    # as MoveIt's TOTG (which unwinds the trajectory first): the waypoints take the continuous
    # joints' values the timing is for, without jumps of a full turn
    trajectory.unwind()
    Q = trajectory.positions
    keep = np.concatenate(([True], np.sqrt((np.diff(Q, axis=0) ** 2).sum(axis=1)) > _REPEATED))
    if not keep.all():
        # as MoveIt's TOTG ("remove repeated points"): a waypoint where the previous one is goes
        # (a controller refuses two points at the same time); a path without two different
        # points is its first waypoint, at rest
        trajectory._keep(keep)
        Q = Q[keep]
    P = PJ = None
    if max_cartesian_speed > 0:
        P, PJ = _link_positions(trajectory, cartesian_speed_limited_link)
    timed = _straight_line(Q, vmax, amax) if P is None and len(Q) > 1 else None
    if timed is None:
        timed = _time_optimal(Q, vmax, amax, grid_points, P, float(max_cartesian_speed) * k, PJ)
    times, V, A = timed
    trajectory.times = times * k  # (exact where k is 1)
    trajectory.velocities = V / k
    trajectory.accelerations = A / k / k  # (k * k may overflow)
    return trajectory


def limit_cartesian_speed(
    trajectory: RobotTrajectory,
    max_speed: float,
    link: str,
    max_velocity_scaling_factor: float = 1.0,
    max_acceleration_scaling_factor: float = 1.0,
) -> RobotTrajectory:
    """Re-time a trajectory so that ``link`` moves no faster than ``max_speed`` [m/s] (MoveIt's
    ``limitMaxCartesianLinkSpeed``), still within the (scaled) joint limits.

    Raises:
        ValueError: ``max_speed`` is not positive or ``link`` is empty.
        KeyError: unknown link.
    """
    if not max_speed > 0:
        raise ValueError(f"max_speed must be positive, got {max_speed}")
    return time_parameterize(
        trajectory, max_velocity_scaling_factor, max_acceleration_scaling_factor, max_speed, link
    )


def slow_to_cartesian_speed(trajectory: RobotTrajectory, max_speed: float, link: str) -> RobotTrajectory:
    """Slow a timed trajectory down (in place) so that ``link`` moves no faster than
    ``max_speed`` [m/s], at its waypoints and on average between them: its times are stretched
    by one factor, which divides its velocities by it and its accelerations by its square (a
    trajectory within its limits stays within them). One that keeps the limit is left as it is.

    Raises:
        ValueError: ``max_speed`` is not positive.
        KeyError: unknown link.
    """
    if not max_speed > 0:
        raise ValueError(f"max_speed must be positive, got {max_speed}")
    if len(trajectory) < 2:
        return trajectory
    P, PJ = _link_positions(trajectory, link)
    times = np.asarray(trajectory.times, dtype=float)
    fastest = 0.0
    if trajectory.velocities is not None:
        fastest = float(np.linalg.norm(np.einsum("nij,nj->ni", PJ, trajectory.velocities), axis=1).max())
    dt = np.diff(times)
    moving = dt > 0.0
    if moving.any():
        fastest = max(fastest, float((np.linalg.norm(np.diff(P, axis=0), axis=1)[moving] / dt[moving]).max()))
    factor = fastest / max_speed
    if factor > 1.0:
        trajectory.times = times * factor
        if trajectory.velocities is not None:
            trajectory.velocities = trajectory.velocities / factor
        if trajectory.accelerations is not None:
            trajectory.accelerations = trajectory.accelerations / (factor * factor)
    return trajectory


# ---------------------------------------------------------------------------------------------
# ruckig: synchronized point-to-point motions


class TrapezoidProfile:
    """Rest-to-rest motion of one coordinate from 0 to ``length`` (> 0) with a trapezoidal speed
    profile: accelerate with ``amax``, cruise at ``vmax`` (if there is room), brake with ``dmax``
    (default ``amax``). Computed by ruckig with unlimited jerk.

    Attributes:
        duration: time of the motion [s].
    """

    def __init__(self, length: float, vmax: float, amax: float, dmax: float | None = None):
        if not (length > 0 and vmax > 0 and amax > 0 and (dmax is None or dmax > 0)):
            raise ValueError(
                f"a trapezoid profile needs positive length and limits, got {length}, {vmax}, {amax}, {dmax}"
            )
        self.length = float(length)
        dmax = amax if dmax is None else dmax
        # ruckig refuses motions of more than about 1e10 s (tiny scaling factors): those are
        # computed k times faster, with limits k (speed) and k^2 (acceleration) times higher,
        # and stretched back; an acceleration that would exceed the speed by 1e12 is capped
        # there (its ramps then last 1e-12 of the motion)
        guess = max(self.length / vmax, math.sqrt(self.length / min(amax, dmax)))
        if not math.isfinite(guess):
            raise ValueError(f"a trapezoid profile of {length} at {vmax}, {amax}, {dmax} lasts longer than a float holds")
        self._k = k = guess if guess > _LONG_PROFILE else 1.0
        speed = vmax * k
        otg = ruckig.Ruckig(1)
        inp = ruckig.InputParameter(1)
        inp.current_position = [0.0]
        inp.target_position = [self.length]
        inp.max_velocity = [float(speed)]
        inp.max_acceleration = [float(min(amax * k * k, 1e12 * speed) if k != 1.0 else amax)]
        inp.min_acceleration = [-float(min(dmax * k * k, 1e12 * speed) if k != 1.0 else dmax)]
        inp.max_jerk = [math.inf]  # infinite jerk: a trapezoidal velocity profile
        self._traj = ruckig.Trajectory(1)
        result = otg.calculate(inp, self._traj)
        if result not in (ruckig.Result.Working, ruckig.Result.Finished):
            raise RuntimeError(f"ruckig could not compute the profile: {result}")
        self.duration = float(self._traj.duration) * k

    def at_time(self, t: float) -> tuple[float, float, float]:
        """``(s, ṡ, s̈)`` at time ``t`` (clamped into [0, duration])."""
        k = self._k
        p, v, a = self._traj.at_time(min(max(float(t), 0.0), self.duration) / k)
        return float(p[0]), float(v[0]) / k, float(a[0]) / k / k

    def time_at(self, s: float) -> float:
        """The time at which the coordinate reaches ``s`` (in [0, length])."""
        if s >= self.length:
            return self.duration
        if s <= 0.0:
            return 0.0
        t = self._traj.get_first_time_at_position(0, float(s))
        return self.duration if t is None else float(t) * self._k


def synchronized_ptp(
    start: np.ndarray, goal: np.ndarray, vmax: np.ndarray, amax: np.ndarray, dmax: np.ndarray | None = None
):
    """A time-optimal rest-to-rest motion on the straight line from ``start`` to ``goal`` with
    trapezoidal velocity profiles that all joints share (fully synchronized, as Pilz's PTP):
    ``q(t) = start + σ(t) (goal - start)`` with one :class:`TrapezoidProfile` ``σ(t)`` from 0 to 1
    whose speed and acceleration are the largest every joint allows.

    Args:
        start, goal: positions.
        vmax, amax: velocity and acceleration limits (positive).
        dmax: deceleration limits (positive; default ``amax``).

    Returns:
        ``(duration, sample)`` where ``sample(t) -> (positions, velocities, accelerations)``.
    """
    start = np.asarray(start, dtype=float)
    goal = np.asarray(goal, dtype=float)
    n = len(start)
    delta = goal - start
    moving = np.abs(delta) > 1e-12
    if n == 0 or not moving.any():
        return 0.0, lambda t: (goal.copy(), np.zeros(n), np.zeros(n))
    span = np.abs(delta[moving])
    dmax = amax if dmax is None else dmax
    profile = TrapezoidProfile(
        1.0,
        float(np.min(np.asarray(vmax, dtype=float)[moving] / span)),
        float(np.min(np.asarray(amax, dtype=float)[moving] / span)),
        float(np.min(np.asarray(dmax, dtype=float)[moving] / span)),
    )

    def sample(t: float):
        s, sd, sdd = profile.at_time(t)
        return start + s * delta, sd * delta, sdd * delta

    return profile.duration, sample
