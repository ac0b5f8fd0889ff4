"""One Reacher physics step, transcribed from SPEC §2.3.1 with explicit matrices and
numpy.linalg.solve: the reference values of `free_motion_matches_hand_computation` and
`violated_wrist_limit_matches_hand_computation` (crates/seads-embodiment/src/reacher.rs).

Independent of the Rust code: it follows the specification step by step, not the Rust
implementation. Run: python3 scripts/reference/reacher_step.py (needs numpy).
"""

import numpy as np

# The constants as SPEC §2.3.1 states them (link 2 combined with the fingertip, about the
# wrist; link 1 about the shoulder; the regulariser weight w0 = (M^-1)_22 at q = 0). The wrist
# limit is the MJCF's ±160°, which the SPEC rounds to 2.7925268.
m2, c2, I2, I1 = 0.0397935069, 0.0573684211, 1.8867358e-4, 2.1411001e-4
L1, H, DAMPING, GEAR = 0.12, 0.02, 0.01, 0.05
W0 = 20740.5487
LIMIT = np.deg2rad(160.0)


def mass(q2):
    cos = np.cos(q2)
    return np.array(
        [
            [I1 + I2 + m2 * L1**2 + 2 * m2 * L1 * c2 * cos, I2 + m2 * L1 * c2 * cos],
            [I2 + m2 * L1 * c2 * cos, I2],
        ]
    )


def impedance(dist):
    x = min(abs(dist) / 0.001, 1.0)
    y = 2 * x**2 if x <= 0.5 else 1 - 2 * (1 - x) ** 2
    return 0.9 + 0.05 * y


def step(q, qd, u):
    q, qd = np.array(q, float), np.array(qd, float)
    tau = GEAR * np.clip(np.array(u, float), -1, 1)
    M = mass(q[1])
    eta = m2 * L1 * c2 * np.sin(q[1])
    bias = np.array([-eta * (2 * qd[0] * qd[1] + qd[1] ** 2), eta * qd[0] ** 2])
    f_smooth = tau - bias - DAMPING * qd
    a0 = np.linalg.solve(M, f_smooth)
    f_con = np.zeros(2)
    if q[1] < -LIMIT or q[1] > LIMIT:
        if q[1] < -LIMIT:
            dist, J = q[1] + LIMIT, np.array([0.0, 1.0])
        else:
            dist, J = LIMIT - q[1], np.array([0.0, -1.0])
        imp = impedance(dist)
        B = 2 / (0.95 * 2 * H)
        K = 1 / (0.95**2 * (2 * H) ** 2)
        a_ref = -B * (J @ qd) - K * imp * dist
        R = (1 - imp) / imp * W0
        Minv = np.linalg.inv(M)
        lam = max(0.0, (a_ref - J @ a0) / (J @ Minv @ J + R))
        f_con = J * lam
    qdd = np.linalg.solve(M + H * DAMPING * np.eye(2), f_smooth + f_con)
    qd_next = qd + H * qdd
    q_next = q + H * qd_next
    return q_next, qd_next


CASES = [
    ([0.3, 1.0], [0.5, -1.2], [0.7, -0.4]),
    ([0.0, 0.0], [0.0, 0.0], [2.0, -3.0]),
    ([1.0, 3.0], [0.1, 0.5], [0.0, 1.0]),
    ([-0.2, -LIMIT - 0.0004], [0.0, -0.3], [0.5, -1.0]),
]

if __name__ == "__main__":
    # The SPEC's w0 is (M^-1)_22 at q = 0 (of the unrounded constants; these agree to 1e-2).
    assert abs(np.linalg.inv(mass(0.0))[1, 1] - W0) < 1e-2, np.linalg.inv(mass(0.0))[1, 1]
    for q, qd, u in CASES:
        q_next, qd_next = step(q, qd, u)
        q = [float(v) for v in q]
        print(f"q {q} qd {qd} u {u} -> q {[float(v) for v in q_next]} qd {[float(v) for v in qd_next]}")
