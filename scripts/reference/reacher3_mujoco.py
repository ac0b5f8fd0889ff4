"""MuJoCo's own physics steps of the planar arms, the reference of the three-link arm
(`crates/seads-embodiment/src/reacher3.rs`) and a check of the two-link Reacher's closed form
against the engine itself.

The two-link model has the physical parameters of the paper's Reacher (dm_control's reacher as
the authors modified it: links of 0.12 m, capsules of radius 0.01 at density 1000, damping 0.01,
gear 0.05, wrist limit ±160°, Euler steps of 0.02 s, no contacts). The three-link model keeps the
reach (0.24 m) and every setting, with three links of 0.08 m and both outer joints limited to
±160°. Both are written here, not copied.

For each model it prints the compiled constants the Rust code uses (per-link mass, centre of
mass, rotational inertia about it, and the limited joints' invweight0) and records single physics
steps from random states: the shoulder anywhere, each limited joint inside its range or beyond
it (half and half, so that one or two limits are active at a time), velocities in [-3, 3] rad/s, controls in [-1.3, 1.3] (clipped by the
model). Output: data/reference/reacher3/steps.json.

Made in a scratch environment: python3 -m venv /tmp/mj && /tmp/mj/bin/pip install mujoco numpy
&& /tmp/mj/bin/python scripts/reference/reacher3_mujoco.py (MuJoCo 4.0.0, numpy 2.x).
"""

import json
import os

import mujoco
import numpy as np

LIMIT = np.deg2rad(160.0)

HEADER = """
  <option timestep="0.02" integrator="Euler"><flag contact="disable"/></option>
  <default>
    <joint type="hinge" axis="0 0 1" damping="0.01"/>
    <motor gear=".05" ctrlrange="-1 1" ctrllimited="true"/>
    <geom density="1000"/>
  </default>
"""

TWO_LINK = f"""<mujoco model="two-link arm">{HEADER}
  <worldbody>
    <body name="upper" pos="0 0 .01">
      <joint name="shoulder"/>
      <geom type="capsule" fromto="0 0 0 .12 0 0" size=".01"/>
      <body name="lower" pos=".12 0 0">
        <joint name="wrist" limited="true" range="-160 160"/>
        <geom type="capsule" fromto="0 0 0 .1 0 0" size=".01"/>
        <body name="tip" pos=".12 0 0"><geom type="sphere" size=".01"/></body>
      </body>
    </body>
  </worldbody>
  <actuator><motor joint="shoulder"/><motor joint="wrist"/></actuator>
</mujoco>"""

THREE_LINK = f"""<mujoco model="three-link arm">{HEADER}
  <worldbody>
    <body name="upper" pos="0 0 .01">
      <joint name="shoulder"/>
      <geom type="capsule" fromto="0 0 0 .08 0 0" size=".01"/>
      <body name="middle" pos=".08 0 0">
        <joint name="elbow" limited="true" range="-160 160"/>
        <geom type="capsule" fromto="0 0 0 .08 0 0" size=".01"/>
        <body name="lower" pos=".08 0 0">
          <joint name="wrist" limited="true" range="-160 160"/>
          <geom type="capsule" fromto="0 0 0 .06 0 0" size=".01"/>
          <body name="tip" pos=".08 0 0"><geom type="sphere" size=".01"/></body>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator><motor joint="shoulder"/><motor joint="elbow"/><motor joint="wrist"/></actuator>
</mujoco>"""


def links(model):
    """Per joint: the rigid body it turns (its body and the bodies fixed to it), as mass, centre
    of mass along the link (x, y in the joint's frame) and inertia about the centre (z axis)."""
    out = []
    for j in range(model.njnt):
        bodies = [b for b in range(model.nbody) if model.body_jntadr[b] == j or
                  (model.body_jntnum[b] == 0 and model.body_parentid[b] != 0 and
                   model.body_jntadr[model.body_parentid[b]] == j)]
        root = model.jnt_bodyid[j]
        mass, first, second = 0.0, np.zeros(2), 0.0
        for b in bodies:
            offset = np.zeros(2) if b == root else model.body_pos[b][:2]
            com = offset + model.body_ipos[b][:2]
            rot = np.zeros(9)
            mujoco.mju_quat2Mat(rot, model.body_iquat[b])
            rot = rot.reshape(3, 3)
            izz = (rot @ np.diag(model.body_inertia[b]) @ rot.T)[2, 2]
            m = model.body_mass[b]
            mass += m
            first += m * com
            second += izz + m * com @ com  # about the joint
        com = first / mass
        out.append({
            "mass": mass,
            "com": list(com),
            "inertia": second - mass * com @ com,
            "length": float(model.body_pos[root + 1][0]),
        })
    return out


def record(xml, n, rng):
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    k = model.nu
    steps = []
    for _ in range(n):
        # The shoulder anywhere; each limited joint inside its range or beyond it by a depth
        # from far below the impedance width (0.001 rad) to 0.3 rad, each case equally often.
        q = np.empty(k)
        q[0] = rng.uniform(0, 2 * np.pi)
        for j in range(1, k):
            if rng.random() < 0.5:
                q[j] = rng.uniform(-LIMIT, LIMIT)
            else:
                q[j] = rng.choice([-1, 1]) * (LIMIT + 10 ** rng.uniform(-4.5, -0.5))
        qd = rng.uniform(-3, 3, k)
        u = rng.uniform(-1.3, 1.3, k)
        mujoco.mj_resetData(model, data)
        data.qpos[:] = q
        data.qvel[:] = qd
        data.ctrl[:] = u
        mujoco.mj_step(model, data)
        steps.append({
            "q": list(q), "qd": list(qd), "u": list(u),
            "q_next": list(data.qpos), "qd_next": list(data.qvel),
        })
    limited = [j for j in range(model.njnt) if model.jnt_limited[j]]
    return {
        "links": links(model),
        "invweight0": {str(j): float(model.dof_invweight0[model.jnt_dofadr[j]]) for j in limited},
        "steps": steps,
    }


def main():
    rng = np.random.default_rng(20261128)
    out = {
        "mujoco": mujoco.__version__,
        "two_link": record(TWO_LINK, 200, rng),
        "three_link": record(THREE_LINK, 400, rng),
    }
    for name in ("two_link", "three_link"):
        print(name, json.dumps(out[name]["links"]), out[name]["invweight0"])
    path = os.path.join(os.path.dirname(__file__), "../../data/reference/reacher3/steps.json")
    with open(path, "w") as f:
        json.dump(out, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
