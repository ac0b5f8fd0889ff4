"""Records reference trajectories of the Jaco environments from the authors' code
(EmbodiedVision/seads-environments: LightsOutJaco, LightsOutJaco with stairs = LightsOut3D,
TileSwapJaco), run unmodified except for one shim: the boards' contact cache, which read
mujoco-py's structured contact array, copies the same fields from the `mujoco` bindings'
contact list.

Per episode: the reset joint positions; per step: the action (9 servo commands in [-1, 1]), the
joint positions after the step (6 arm joints, 3 fingers), the pinch and grip sites' world
positions, and the press (LightsOut: the field, row-major; TileSwap: the swapped cells a < b as
a·9 + b; -1 for none) with its normalised board position. Also the world positions of the
board's sites (LightsOut: the 25 field centres; TileSwap: the board centre).

Episodes: 20 under uniformly random actions, 20 holding one random servo command (which the
servos reach), 50 steps each or until a press ends the episode; actions drawn from NumPy
generators seeded 1000 + episode; environment seeds 0..39.

The scratch environment it ran in (2026-11-24; nothing of it is a dependency of the project):
    python3 -m venv /tmp/mjenv
    /tmp/mjenv/bin/pip install dm-control==1.0.50 "mujoco==3.17.0" "numpy<2" "matplotlib<3.9" \
        "pandas<2.3" gym==0.26.2 h5py joblib tqdm
    # the authors' environments, from github.com/EmbodiedVision/seads-environments (HEAD), in
    # /tmp/seadsenv; their board files are Git LFS objects, so they were regenerated with that
    # repository's own seads_envs/board_games/bfs_reverse.py (store_boards; LightsOut to depth
    # 6, TileSwap complete).
    for board in lightsout lightsout3d tileswap; do
        MUJOCO_GL=disable /tmp/mjenv/bin/python scripts/reference/jaco_record.py \
            data/reference/jaco/${board}_jaco.json $board
    done
"""
import json
import sys

sys.path.insert(0, '/tmp/seadsenv')
import numpy as np
from seads_envs.hybrid.jaco import lightsout_board


class Contacts:
    class One:
        def __init__(self, pos):
            self.pos = pos

    def __init__(self, c):
        self.geom1 = np.array(c.geom1)
        self.geom2 = np.array(c.geom2)
        self._pos = np.array(c.pos)

    def __getitem__(self, i):
        return Contacts.One(self._pos[i])


def before_substep(self, physics, random_state):
    self._contact_from_before_substep = Contacts(physics.data.contact)


lightsout_board.LightsOutBoard.before_substep = before_substep
from seads_envs.hybrid.jaco import tileswap_board  # noqa: E402

tileswap_board.TileSwapBoard.before_substep = before_substep
from seads_envs.hybrid.jaco.lightsout import LightsOutJacoEnv  # noqa: E402
from seads_envs.hybrid.jaco.tileswap import TileSwapJacoEnv  # noqa: E402

board = sys.argv[2] if len(sys.argv) > 2 else 'lightsout'
if board == 'tileswap':
    env = TileSwapJacoEnv(reset_split='train', max_solution_depth=5, random_solution_depth=True)
else:
    env = LightsOutJacoEnv(reset_split='train', max_solution_depth=5, random_solution_depth=True,
                           stairs=(board == 'lightsout3d'))
side = 3 if board == 'tileswap' else 5
dm = env._gym_env._env
r6 = lambda a: [round(float(x), 6) for x in a]
episodes = []
for e in range(40):
    env.seed(e) if hasattr(env, 'seed') else None
    rng = np.random.default_rng(1000 + e)
    env.reset()
    # Seeding rebuilds the dm_control environment: take the live one.
    dm = env._gym_env._env
    physics = dm.physics
    ep = {
        'kind': 'random' if e < 20 else 'constant',
        'seed': e,
        'qpos0': r6(physics.data.qpos[:9]),
        'pinch0': r6(physics.named.data.site_xpos['jaco_arm/jaco_hand/pinchsite']),
        'steps': [],
    }
    held = rng.uniform(-1, 1, 9)
    for t in range(50):
        action = rng.uniform(-1, 1, 9) if e < 20 else held
        _, _, done, info = env.step(action.astype(np.float32))
        c = info.get('contact_info')
        pressed = -1
        if c is not None and board != 'tileswap':
            pressed = int(c.row) * 5 + int(c.col)
        elif c is not None:
            # TileSwap: the swapped pair of cells (row-major), as one number a * 9 + b, a < b.
            a, b = sorted(int(i[0]) * 3 + int(i[1]) for i in c.swap_indices)
            pressed = a * 9 + b
        ep['steps'].append({
            'action': r6(action),
            'qpos': r6(physics.data.qpos[:9]),
            'pinch': r6(physics.named.data.site_xpos['jaco_arm/jaco_hand/pinchsite']),
            'grip': r6(physics.named.data.site_xpos['jaco_arm/jaco_hand/gripsite']),
            'pressed': pressed,
            'contact': r6(c.norm_pos) if c is not None else None,
        })
        if done:
            # The reference resets the arm after a move; the episode ends here.
            break
    episodes.append(ep)
    print(e, ep['kind'], len(ep['steps']), 'pressed', [s['pressed'] for s in ep['steps'] if s['pressed'] >= 0], flush=True)

site_names = [dm.physics.model.id2name(i, 'site') for i in range(dm.physics.model.nsite)]
fields = [r6(dm.physics.named.data.site_xpos[n]) for n in site_names if not n.startswith('jaco_arm')]
import mujoco, dm_control
out = {
    'made_with': {'mujoco': mujoco.__version__, 'dm_control': dm_control.__version__ if hasattr(dm_control, '__version__') else '1.0.50',
                  'physics_timestep': dm.physics.timestep(), 'control_timestep': dm.control_timestep()},
    'board': board,
    'field_sites': fields,
    'episodes': episodes,
}
json.dump(out, open(sys.argv[1], 'w'), separators=(',', ':'))
print('wrote', sys.argv[1])
