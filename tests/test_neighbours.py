"""A decision's neighbours: motion turned about the vertical, contact moved along the surface's horizontal tangent."""

import math

import numpy as np

from primitives.training.neighbours import CONTACT_M, MOTION_RAD, neighbour_decisions, surface_tangent


def test_the_four_neighbours_turn_the_motion_and_slide_the_contact():
    contact = np.array([0.5, 0.1, 0.03])
    normal = np.array([-1.0, 0.0, 0.0])  # a face looking along -x, pushed along +x
    motion = np.array([0.8, 0.0, -0.2])
    (c1, m1), (c2, m2), (c3, m3), (c4, m4) = neighbour_decisions(contact, normal, motion)
    assert np.array_equal(c1, contact) and np.array_equal(c2, contact)
    for m, sign in ((m1, 1.0), (m2, -1.0)):
        assert math.isclose(np.linalg.norm(m), np.linalg.norm(motion))
        assert math.isclose(m[2], motion[2])  # turned about the vertical
        assert math.isclose(math.atan2(m[1], m[0]), sign * MOTION_RAD, abs_tol=1e-12)
    assert np.array_equal(m3, motion) and np.array_equal(m4, motion)
    assert np.allclose(c3 - contact, [0.0, CONTACT_M, 0.0]) and np.allclose(c4 - contact, [0.0, -CONTACT_M, 0.0])


def test_the_tangent_is_horizontal_and_on_a_flat_top_x():
    n = np.array([0.6, 0.0, 0.8])
    t = surface_tangent(n)
    assert math.isclose(np.linalg.norm(t), 1.0) and abs(t @ n) < 1e-12 and t[2] == 0.0
    assert np.array_equal(surface_tangent(np.array([0.0, 0.0, 1.0])), [1.0, 0.0, 0.0])
    (_, _), (_, _), (c, _), _ = neighbour_decisions(np.zeros(3), np.array([0.0, 0.0, 1.0]), np.array([1.0, 0, 0]),
                                                    contact_m=0.005)
    assert np.allclose(c, [0.005, 0.0, 0.0])
