"""ComputeIK: turn the target poses of a generator's states into robot states.

MTC's ``stages/compute_ik.h`` (semantics §2.3). ComputeIK wraps a generator (usually of the
``GeneratePose`` family) whose states carry a ``target_pose`` (and possibly an ``ik_frame``)
property. For each of the child's solutions, cheapest first, it

1. inherits the properties configured for it (``configureInitFrom(INTERFACE, ["target_pose"])``)
   from the solution's state; a ``target_pose`` neither set nor configured is read from that
   state too (MTC would fail: "Property 'target_pose': undefined"),
2. resolves the end effector / group, the target in the planning frame and the IK frame
   (a link, an attached object or an object's subframe, plus an offset on it),
3. unless ``ignore_collisions``, checks the end-effector links placed at the target against
   the world ("<upstream comment> eef in collision: a - b, c - d"),
4. solves IK, first from the scene's state, then from random seeds, and spawns every
   distinct candidate (closer than ``min_solution_distance`` to an earlier one counts as
   the same): valid ones with cost = upstream cost + joint distance to ``default_pose`` (or
   to the start state), colliding ones as failures "Collision between a - b", ones
   violating ``constraints`` as failures "Constraints violated" (both before the upstream
   comment, on a line of their own); with none at all, "<upstream comment> no IK found".
   As in MTC, the search stops once ``max_ik_solutions`` candidates are recorded, valid or
   not, checked after each IK call (descents until one finds a valid candidate).

ComputeIK spawns its own solutions (``SubTrajectory`` without trajectory), not wrapped ones.

Determinism (beyond MTC): the random IK seeds come from a generator seeded with the ``seed``
property and the number of child solutions handled since ``reset()``, and the search makes
at most ``max_ik_attempts`` descents per wanted solution, none of them cut short by the clock.
A target none of the first ``max_ik_attempts`` descents reaches is given up ("no IK found")
instead of spending the budgets of the other wanted solutions on it as well.
MTC's default ``timeout`` is the group's IK timeout, the budget of one IK call; here every
descent is such a call, so the default ``timeout`` is the group's IK timeout times the number
of descents allowed. The attempt budget then ends the search, not the clock, and the same
task gives the same IK solutions on any machine. A ``timeout`` set by the user still bounds
the search (and may end it earlier on a slow machine).
"""

from __future__ import annotations

import math
import time

import numpy as np

from mtc import msgs
from mtc.core.container import WrapperBase
from mtc.core.properties import unsigned_int, valid_message
from mtc.core.stage import InitStageError, Stage
from mtc.core.storage import InterfaceState, SolutionBase, SubTrajectory
from mtc.scene.frames import rigid_inverse
from mtc.stages._common import (
    FrameError,
    first_collision_pair,
    format_collision_pairs,
    ik_frame_from_args,
    pose_stamped_from_args,
    resolve_frame,
)
from mtc.stages.generate_pose import SolutionQueue, frame_marker

__all__ = ["ComputeIK"]


def eef_collisions(scene, link: str, link_target: np.ndarray) -> list[tuple[str, str]]:
    """Collisions of ``link``, the links below it and the objects attached to them, were
    ``link`` placed at ``link_target`` (4x4, planning frame) with the rest of the state
    unchanged; the collisions of the moving links above are allowed (MTC's
    ``isTargetPoseCollidingInEEF``).

    The scene's own end-effector-at-pose check moves the bodies' placements in the scene's
    collision set-up (built once per scene and shared by the candidates' diffs), instead of
    a probe scene with moved world objects and a collision set-up of its own per target:
    the same pairs at under half the cost.
    """
    return scene.get_link_collisions_at(link, link_target)


def eef_marker(scene, link: str, link_target: np.ndarray) -> dict:
    """MTC's "ik target" marker: ``link`` and the links below it (the end effector, as the
    viewer draws them, half transparent) placed so that ``link`` lies at ``link_target``
    (4x4, planning frame), the rest of the state as in ``scene``. The poses are nested lists
    of floats, so that messages holding the marker compare by value."""
    state = scene.current_state
    shift = link_target @ rigid_inverse(state.get_global_link_transform(link))
    links = {name: (shift @ state.get_global_link_transform(name)).tolist()
             for name in scene.robot_model.descendant_link_names(link)}
    return {"type": "links", "ns": "ik target", "name": link, "frame_id": scene.planning_frame,
            "links": links, "opacity": 0.5}


class ComputeIK(WrapperBase):
    """Solve IK for the target poses of the wrapped generator's states.

    Args:
        name: Stage name.
        stage: The wrapped generator (may be inserted later with ``insert()``).

    Properties:
        eef: End effector; its parent group is the default ``group``, its parent link the
            default IK link.
        group: Planning group to solve for.
        default_pose: Named state of the group the cost is measured to ("" = the start state).
        max_ik_solutions: Distinct IK solutions wanted per target (default 1).
        ignore_collisions: Accept colliding solutions (default False).
        min_solution_distance: Joint distance below which two solutions are the same (0.1).
        constraints: ``msgs.Constraints`` every solution must satisfy.
        ik_frame: ``PoseStamped`` of the robot frame to put at the target (default: the eef's
            parent link or the group's tip); a link, attached object or ``"object/subframe"``.
        target_pose: ``PoseStamped`` to reach (read from the child's states by default).
        timeout: Time limit per target [s] (default: the group's IK timeout per allowed descent).
        seed: Seed of the random IK restarts (default 0).
        max_ik_attempts: IK descents per wanted solution (default 20); when none of the first
            ``max_ik_attempts`` descents converges, the target counts as unreachable.
    """

    def __init__(self, name: str = "IK", stage: Stage | None = None):
        super().__init__(name, stage)
        p = self.properties
        p.declare("eef", None, "name of end-effector", type=str)
        p.declare("group", None, "name of active group (derived from eef if not provided)", type=str)
        p.declare("default_pose", "", "default joint pose of active group (defines cost of IK)")
        p.declare("max_ik_solutions", 1, "maximum number of IK solutions per target", type=unsigned_int)
        p.declare("ignore_collisions", False, "accept colliding IK solutions")
        p.declare("min_solution_distance", 0.1,
                  "minimum distance between separate IK solutions for the same target", type=float)
        p.declare("constraints", msgs.Constraints(), "constraints to maintain during trajectory")
        p.declare("ik_frame", None, "frame to be moved towards goal pose", type=msgs.PoseStamped,
                  convert=valid_message("ik_frame"))
        p.declare("target_pose", None, "goal pose for ik frame", type=msgs.PoseStamped,
                  convert=valid_message("target_pose"))
        p.declare("seed", 0, "seed of the random IK restarts", type=int)
        p.declare("max_ik_attempts", 20, "IK descents (the first from the start state) per wanted solution",
                  type=unsigned_int)
        self._upstream = SolutionQueue()
        self._consumed = 0

    # --- configuration (MTC's setters) --------------------------------------------------
    def setEndEffector(self, eef: str) -> None:
        """Set ``eef``."""
        self.properties.set("eef", eef)

    def setGroup(self, group: str) -> None:
        """Set ``group``."""
        self.properties.set("group", group)

    def setIKFrame(self, *args) -> None:
        """``setIKFrame(PoseStamped)``, ``setIKFrame(pose, link)`` or ``setIKFrame(link)``."""
        self.properties.set("ik_frame", ik_frame_from_args(*args))

    def setTargetPose(self, *args) -> None:
        """``setTargetPose(PoseStamped)`` or ``setTargetPose(pose, frame="")``."""
        self.properties.set("target_pose", pose_stamped_from_args("setTargetPose", *args, default_frame=""))

    def setMaxIKSolutions(self, n: int) -> None:
        """Set ``max_ik_solutions``."""
        self.properties.set("max_ik_solutions", n)

    def setIgnoreCollisions(self, ignore: bool) -> None:
        """Set ``ignore_collisions``."""
        self.properties.set("ignore_collisions", ignore)

    def setMinSolutionDistance(self, distance: float) -> None:
        """Set ``min_solution_distance``."""
        self.properties.set("min_solution_distance", distance)

    # --- lifecycle ----------------------------------------------------------------------
    def reset(self) -> None:
        super().reset()
        self._upstream.clear()
        self._consumed = 0

    def init(self, robot_model) -> None:
        errors = InitStageError.collect(super().init, robot_model)
        # eef and group may also come from the interface; validate what is known now
        for problem in self._groups(robot_model)[2]:  # one entry each, as MTC
            errors.push_back(self, problem)
        if errors:
            raise errors

    def _groups(self, robot_model):
        """``(eef, group JointModelGroup or None, list of problems)``."""
        p = self.properties
        eef = p.get("eef", None)
        group = p.get("group", None)
        problems = []
        eef_model = None
        if eef is not None:
            if eef in robot_model.end_effectors:
                eef_model = robot_model.get_end_effector(eef)
            else:
                problems.append(f"Unknown end effector: {eef}")
        jmg = None
        if group is not None:
            if robot_model.has_joint_model_group(group):
                jmg = robot_model.get_joint_model_group(group)
            else:
                problems.append(f"Unknown group: {group}")
        elif eef_model is not None:
            jmg = robot_model.get_joint_model_group(eef_model.parent_group)
        return eef_model, jmg, problems

    # --- computing ----------------------------------------------------------------------
    def onNewSolution(self, solution: SolutionBase) -> None:
        self._upstream.push(solution)

    def canCompute(self) -> bool:
        return bool(self._upstream) or super().canCompute()

    def compute(self) -> None:
        if super().canCompute():
            super().compute()
        if not self._upstream:
            return
        s = self._upstream.pop()
        self._solve(s)

    def _fail(self, s: SolutionBase, comment: str, scene=None, markers=()) -> None:
        solution = SubTrajectory.failure(comment)
        solution.markers.extend(markers)
        self.spawn(InterfaceState(scene if scene is not None else s.start.scene.diff()), solution)

    def _target_pose(self, s: SolutionBase):
        """``target_pose`` as MTC reads it, or, when it is neither set nor configured to come
        from anywhere, the one on the child's state (MTC needs
        ``configureInitFrom(INTERFACE, ["target_pose"])`` for that; leaving the property
        unconfigured keeps the user's own configuration free, as in MTC)."""
        p = self.properties
        value = p.get("target_pose", None)
        state_props = s.start.properties
        if value is None and "target_pose" in state_props and not p.property("target_pose").initsFrom(
                Stage.PARENT | Stage.INTERFACE):
            value = state_props.get("target_pose", None)
        return value if value is not None else p.get("target_pose")  # undefined: MTC's error

    def _solve(self, s: SolutionBase) -> None:
        p = self.properties
        p.performInitFrom(Stage.INTERFACE, s.start.properties)
        scene = s.start.scene
        model = scene.robot_model

        # 1. end effector and group
        eef_model, jmg, problems = self._groups(model)
        if problems:
            self._fail(s, problems[0])  # MTC stops at the first
            return
        if jmg is None:
            self._fail(s, "Neither eef nor group are well defined")
            return
        # 2. timeout default: MTC's is the group's IK timeout (the budget of one IK call); here
        # each descent is such a call, so the default allows the group's IK timeout per descent
        # and the attempt budget, not the clock, ends the search (see the module docstring)
        max_solutions = p.get("max_ik_solutions")
        attempts_per_solution = max(1, p.get("max_ik_attempts"))
        max_attempts = attempts_per_solution * max(1, max_solutions)
        p.property("timeout").setDefaultValue(float(jmg.default_ik_timeout) * max_attempts)

        # 3. target pose in the planning frame
        target_msg = msgs.from_dict(msgs.PoseStamped, msgs.to_dict(self._target_pose(s)))
        frame = target_msg.header.frame_id
        if not frame:
            target_msg.header.frame_id = frame = scene.planning_frame
        if not scene.knows_frame_transform(frame):
            self._fail(s, f"Unknown reference frame for target pose: '{frame}'")
            return
        target = scene.get_frame_transform(frame) @ msgs.pose_to_matrix(target_msg.pose)

        # 4. IK link and the offset of the IK frame on it
        ik_frame = p.get("ik_frame", None)
        if ik_frame is None:
            if eef_model is not None:
                tip = eef_model.parent_link
            elif len(jmg.end_effector_tips) == 1:
                tip = jmg.end_effector_tips[0]
            else:
                self._fail(s, "Failed to derive IK target link")
                return
            ik_frame = msgs.identity_pose_stamped(tip)
        try:
            link, frame_offset = resolve_frame(scene, ik_frame.header.frame_id)
        except FrameError:
            if ik_frame.header.frame_id != scene.planning_frame:
                self._fail(s, f"ik frame unknown in robot: '{ik_frame.header.frame_id}'")
                return
            # a MoveIt robot state knows its model frame as its root link (whose IK, for a
            # fixed base, finds nothing)
            link, frame_offset = model.root_link_name, np.eye(4)
        offset = frame_offset @ msgs.pose_to_matrix(ik_frame.pose)
        link_target = target @ rigid_inverse(offset)
        eef = eef_marker(scene, link, link_target)
        markers = [frame_marker(self.markerNS(), "target frame", target_msg),
                   frame_marker(self.markerNS(), "ik frame", ik_frame), eef]
        # as MTC, the end effector at a target that fails is drawn red
        failed_markers = [*markers[:2], dict(eef, color="red")]

        # 5. the end effector alone at the target must not collide with the world
        ignore_collisions = p.get("ignore_collisions")
        if not ignore_collisions:
            pairs = eef_collisions(scene, link, link_target)
            if pairs:
                # (semantics §2.3: the upstream comment, then " eef in collision: a - b, c - d")
                pairs = sorted(tuple(sorted(p[:2])) for p in pairs)
                self._fail(s, f"{s.comment} eef in collision: {format_collision_pairs(pairs)}", markers=failed_markers)
                return

        # 6. reference for the cost
        from mtc.planners import ik as ik_module

        try:
            solver = ik_module.get_ik_solver(model, jmg.name, link)
        except ik_module.UnmovedLinkError:
            # no variable of the group moves the IK frame
            self._fail(s, f"{s.comment} no IK found", markers=failed_markers)
            return
        start_q = scene.current_state.positions.copy()
        reference = start_q.copy()
        default_pose = p.get("default_pose")
        if default_pose:
            reference_state = scene.current_state.copy()
            try:
                reference_state.set_to_default_values(jmg.name, default_pose)
            except KeyError as e:
                self._fail(s, f"unknown default_pose: {e.args[0]}")
                return
            reference = reference_state.positions.copy()

        constraints = p.get("constraints")
        constraint_set = None
        if constraints is not None and (constraints.joint_constraints or constraints.position_constraints
                                        or constraints.orientation_constraints):
            from mtc.planners.constraints import KinematicConstraintSet

            try:
                # bound once to the scene (its frames; unknown ones fail here): the candidates'
                # scenes differ from it only in the robot state
                constraint_set = KinematicConstraintSet(model, constraints).bind(scene)
            except (KeyError, ValueError) as e:
                self._fail(s, f"invalid constraints: {msgs.error_text(e)}", markers=failed_markers)
                return

        # 7. IK: the start state first, then random seeds; every distinct candidate is spawned
        min_distance = p.get("min_solution_distance")
        if not ignore_collisions:
            # build the scene's collision set-up now (the candidates' scenes share it), so its
            # one-time cost is not taken from the IK time budget
            scene.is_state_colliding(scene.current_state, jmg.name)
        rng = np.random.default_rng([int(p.get("seed")) & 0xFFFFFFFF, self._consumed])
        self._consumed += 1
        # the clock starts after all set-up, so only IK and checks count against the timeout
        deadline = time.perf_counter() + float(p.get("timeout"))
        idx = np.asarray(jmg.variable_indices, dtype=int)
        # As MTC, the loop runs while fewer candidates than max_ik_solutions are recorded, valid
        # or not, and each round is one IK call (MoveIt's setFromIK with a validity callback):
        # descents until one records a valid candidate, recording the invalid ones on the way.
        recorded: list[np.ndarray] = []
        attempts = 0
        while len(recorded) < max_solutions and attempts < max_attempts:
            succeeded = False
            call_attempts = 0
            while call_attempts < attempts_per_solution and attempts < max_attempts:
                if attempts > 0 and time.perf_counter() >= deadline:
                    break
                q = start_q.copy()
                if attempts > 0:
                    q[idx] = solver.random_positions(rng)
                    model.enforce_mimic(q)
                attempts += 1
                call_attempts += 1
                # one descent from q, never cut short by the clock (its result must not depend on speed)
                solved = solver.solve(link_target, q, timeout=math.inf, random_restarts=False)
                if not solved:
                    continue
                q = solved[0]
                if any(solver.group_distance(q, r) < min_distance for r in recorded):
                    continue  # the same solution again: not recorded
                recorded.append(q)
                succeeded = self._spawn_candidate(s, q, jmg, ignore_collisions, constraint_set, solver, reference,
                                                  markers)
                if succeeded:
                    break
            if not succeeded and (max_solutions == 1 or not recorded or time.perf_counter() >= deadline):
                # MTC stops after a failed call when one solution is wanted; beyond MTC, a call
                # whose descents all missed means the target is out of reach (the remaining
                # budgets would fail as well: for the demo's grasp angles the arm cannot take),
                # while a reachable target converges within a few descents (the demo's: 16)
                break

        # 8. nothing at all
        if not recorded:
            self._fail(s, f"{s.comment} no IK found", markers=failed_markers)

    def _spawn_candidate(self, s: SolutionBase, q: np.ndarray, jmg, ignore_collisions: bool, constraint_set,
                         solver, reference: np.ndarray, markers) -> bool:
        """Spawn a recorded IK candidate (a failure if it collides or violates the
        constraints, with MTC's comments); True if it is valid."""
        new_scene = s.start.scene.diff()
        new_scene.current_state.positions = q
        state = new_scene.current_state
        solution = SubTrajectory(None, 0.0, s.comment)
        solution.markers.extend(markers)
        valid = False
        if not ignore_collisions and new_scene.is_state_colliding(state, jmg.name):
            a, b = first_collision_pair(new_scene.get_collisions(state, jmg.name))
            solution.markAsFailure(f"Collision between {a} - {b}")  # (semantics §2.3; one contact)
        elif constraint_set is not None and not constraint_set(state.positions):
            solution.markAsFailure("Constraints violated")
        else:
            solution.cost = s.cost + solver.group_distance(q, reference)
            valid = True
        new_state = InterfaceState(new_scene)
        self.forwardProperties(s.start, new_state)
        self.spawn(new_state, solution)
        return valid
