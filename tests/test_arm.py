"""The 7-DOF arm: pushes like the finger, tracks its target, clears walls in transit, refuses the unreachable."""

from __future__ import annotations

import numpy as np
import pytest

import affordplan as ap
from affordplan.errors import ReachabilityError
from affordplan.sim.arm import HOME, ArmIK
from primitives import rewards


def face_push(sim: ap.Simulator, xy=(0.5, 0.0), stroke: float = 2.0 / 3.0) -> ap.Outcome:
    T0 = sim.reset(resting_state=0, xy=xy, yaw=0.0)
    return sim.execute(T0[:3, 3] - np.array([0.05, 0.0, 0.0]), (stroke, 0.0, 0.0), normal=(-1.0, 0.0, 0.0))


def test_arm_push_moves_the_cube_like_the_finger(cube):
    by_arm = face_push(ap.Simulator(cube, pusher="arm"))
    by_finger = face_push(ap.Simulator(cube, pusher="finger"))
    assert by_arm.approach_ok and by_arm.valid
    gap = np.linalg.norm(by_arm.pose_after[:3, 3] - by_finger.pose_after[:3, 3])
    assert gap < 0.02
    m = rewards.motion(by_arm.pose_before, by_arm.pose_after)
    assert 0.04 <= m.p[0] <= 0.09 and m.theta_deg < 5.0
    assert by_arm.tracking_error_max <= 0.005
    assert by_arm.tracking_error_median <= by_arm.tracking_error_max


class ForceProbe(ap.Simulator):
    """Records the contact force the arm feels after each control chunk (N)."""

    def _step(self, n, guarded=True):
        super()._step(n, guarded)
        self.forces = getattr(self, "forces", []) + [float(np.linalg.norm(self._pusher.contact_force()))]


@pytest.mark.parametrize("limited", [True, False])
def test_pressing_down_on_a_cube_is_force_limited(cube, monkeypatch, limited):
    """A full downward motion (9 cm into the cube's top): the arm, limited to 15 N (about the training finger's
    cap), feels ~45 N on average (the limit acts a chunk late); without the limit its stiff joints press with
    ~200 N."""
    if not limited:
        monkeypatch.setattr(ap.sim.pushers.ArmPusher, "max_force", 1e9)
    sim = ForceProbe(cube, pusher="arm")
    T0 = sim.reset(resting_state=0, xy=(0.55, 0.0), yaw=0.0)
    sim.forces = []
    out = sim.execute(T0[:3, 3] + np.array([0.0, 0.0, 0.05]), (0.0, 0.0, -1.0), normal=(0.0, 0.0, 1.0))
    assert out.approach_ok and out.valid, out.invalid_reason
    assert np.linalg.norm(out.pose_after[:3, 3] - T0[:3, 3]) < 0.005  # pressed, not moved
    pressing = [f for f in sim.forces if f > 1.0]
    assert len(pressing) > 50  # 1.5 s of motion steps
    mean = float(np.mean(pressing))
    assert (mean < 80.0) if limited else (mean > 150.0), mean


def test_no_arm_link_touches_a_wall_between_home_and_object(cube):
    """The wall stands between the arm's home pose and the cube; the arm transits over it."""
    wall = ap.Box(center=(0.45, 0.0), size=(0.03, 0.5, 0.16))
    sim = ap.Simulator(cube, obstacles=[wall], pusher="arm")
    T0 = sim.reset(resting_state=0, xy=(0.62, 0.0), yaw=0.0)
    home_tip = sim.data.site_xpos[sim.model.site("fingertip").id].copy()
    assert home_tip[0] < 0.45 < T0[0, 3]  # home is on the near side of the wall

    m, d = sim.model, sim.data
    wall_geom = m.geom("obstacle0").id
    arm_bodies = {m.body(n).id for n in ("link1", "link2", "link3", "link4", "link5", "link6", "link7", "hand")}
    touches = []

    def read_contacts(s: ap.Simulator) -> None:
        for c in d.contact[: d.ncon]:
            g1, g2 = int(c.geom1), int(c.geom2)
            if wall_geom in (g1, g2):
                other = g2 if g1 == wall_geom else g1
                if int(m.geom_bodyid[other]) in arm_bodies:
                    touches.append(m.geom(other).name)

    sim.on_chunk = read_contacts
    # Contact on the far (+x) face, pushing back towards the wall: the arm must pass over it.
    out = sim.execute(T0[:3, 3] + np.array([0.05, 0.0, 0.0]), (-0.3, 0.0, 0.0), normal=(1.0, 0.0, 0.0))
    assert out.approach_ok
    assert touches == []
    assert all("obstacle0" not in pair for pair in out.arm_collisions)


def test_unreachable_contact_raises_at_once(cube):
    sim = ap.Simulator(cube, pusher="arm")
    T0 = sim.reset()
    steps = sim.physics_steps
    with pytest.raises(ReachabilityError, match="cannot reach"):
        sim.execute((1.3, 0.6, 0.05), (1.0, 0.0, 0.0), normal=(-1.0, 0.0, 0.0))
    assert sim.physics_steps == steps  # raised before any physics: no silent no-op, no hang
    assert np.array_equal(sim.object_pose(), T0)


@pytest.mark.parametrize("x, y", [(0.3, -0.3), (0.3, 0.3), (0.75, -0.3), (0.75, 0.3), (0.75, 0.0), (0.5, 0.0)])
def test_the_arm_reaches_the_whole_workspace_low_and_pointing_down(x, y):
    ik = ArmIK()
    ik.check_reachable([np.array([x, y, 0.01]), np.array([x, y, 0.15])], np.array(HOME))


def test_arm_determinism(cube):
    poses = []
    for _ in range(2):
        sim = ap.Simulator(cube, pusher="arm")
        poses.append(face_push(sim, xy=(0.55, 0.1), stroke=0.8).pose_after)
    assert np.array_equal(poses[0], poses[1])


def test_a_contact_under_the_mugs_handle_fails_its_approach_without_lifting_the_mug():
    """The pre-contact point lies under the lying mug's handle: coming down onto it would hook the handle.

    Before the arm checked its way down, this very call (a roll the learned policy chose in the demo)
    carried the mug 17 cm up on the fingertip and the ``off_table`` guard ended the run.
    """
    mug = ap.load_object("mug")
    sim = ap.Simulator(mug, pusher="arm", seed=0)
    T0 = sim.reset(resting_state=0, xy=(0.45, -0.05), yaw=0.5)
    contact = np.array([0.42040747, -0.05431026, 0.05077498])
    normal = sim.surface_normal(contact)
    pre = contact + (sim._pusher.radius + sim.protocol.standoff) * normal
    assert not sim._pusher.can_descend_to(pre)
    assert sim._pusher.can_descend_to(np.array([0.6, 0.2, 0.03]))  # open table
    out = sim.execute(contact, (-0.76, -0.69, 0.01))
    assert out.valid and not out.approach_ok
    assert np.linalg.norm(out.pose_after[:3, 3] - T0[:3, 3]) < 0.005  # untouched: still where it was
    assert mug.classify(out.pose_after) == 0


STRETCHED = (0.179, 1.0611, 0.0125, -0.4512, -0.011, 1.5301, 0.7874)  # the arm after a push to x = 0.71 m (plan bench)


def test_an_arm_stretched_by_a_far_push_is_homed_instead_of_refusing_what_it_reaches(cube):
    sim = ap.Simulator(cube, pusher="arm")
    T0 = sim.reset(resting_state=0, xy=(0.68, 0.0), yaw=0.0)
    contact, far_normal = T0[:3, 3] + np.array([0.05, 0.0, 0.0]), np.array([1.0, 0.0, 0.0])
    _, touch, pre = sim._approach_points(contact, far_normal)
    sim._pusher.set_q(STRETCHED)
    with pytest.raises(ReachabilityError):  # IK seeded with the stretched arm stalls short of the far face
        sim._ik.check_reachable([pre, touch], sim._pusher.q)
    out = sim.execute(contact, (-2.0 / 3.0, 0.0, 0.0), normal=far_normal)  # homed, then pushed towards the base
    m = rewards.motion(out.pose_before, out.pose_after)
    assert out.approach_ok and out.valid
    assert -0.09 <= m.p[0] <= -0.04 and abs(m.p[1]) < 0.01 and m.theta_deg < 5.0

    far = ap.Simulator(cube, pusher="arm")
    T1 = far.reset(resting_state=0, xy=(0.72, 0.0), yaw=0.0)  # its far face is beyond the reach from HOME too
    far._pusher.set_q(STRETCHED)
    steps = far.physics_steps
    with pytest.raises(ReachabilityError, match="cannot reach"):
        far.execute(T1[:3, 3] + np.array([0.05, 0.0, 0.0]), (-2.0 / 3.0, 0.0, 0.0), normal=far_normal)
    assert far.physics_steps == steps and np.array_equal(far.object_pose(), T1)


def test_an_arm_snapshot_restores_the_arms_own_state_too(cube):
    """The arm keeps its commanded target, force-limit offset and IK configuration outside MuJoCo's state: after a
    restore the same push is the same, bit for bit, though the arm ended the first one elsewhere."""
    sim = ap.Simulator(cube, pusher="arm")
    T0 = sim.reset(resting_state=0, xy=(0.55, 0.1), yaw=0.0)
    start = sim.snapshot()
    contact, motion, normal = T0[:3, 3] - np.array([0.05, 0.0, 0.0]), (0.8, 0.0, 0.0), (-1.0, 0.0, 0.0)
    first = sim.execute(contact, motion, normal=normal)
    assert first.valid and rewards.motion(first.pose_before, first.pose_after).p[0] > 0.04
    sim.restore(start)
    again = sim.execute(contact, motion, normal=normal)
    assert np.array_equal(again.pose_after, first.pose_after)
    assert again.tracking_error_max == first.tracking_error_max
