"""Gymnasium environments on MuJoCo for hexapod robots (see docs/architecture.md).

Importing the package registers the env ids with Gymnasium:

>>> import gymnasium as gym, hexapod_envs
>>> env = gym.make("HexapodCliffWalk-v0")
"""

import gymnasium
from gymnasium.envs.registration import register

__version__ = "0.1.0"

register(
    id="HexapodCliffWalk-v0",
    entry_point="hexapod_envs.envs.cliff_walk:CliffWalkEnv",
    vector_entry_point="hexapod_envs.vector:cliff_walk",
    max_episode_steps=1500,
)

register(
    id="HexapodStewartTilt-v0",
    entry_point="hexapod_envs.envs.stewart_tilt:StewartTiltEnv",
    vector_entry_point="hexapod_envs.vector:stewart_tilt",
    max_episode_steps=1600,
)

register(
    id="HexapodIrregularTerrain-v0",
    entry_point="hexapod_envs.envs.irregular_terrain:IrregularTerrainEnv",
    vector_entry_point="hexapod_envs.vector:irregular_terrain",
    max_episode_steps=1200,
)

register(
    id="HexapodDitchCrossing-v0",
    entry_point="hexapod_envs.envs.ditch_crossing:DitchCrossingEnv",
    vector_entry_point="hexapod_envs.vector:ditch_crossing",
    max_episode_steps=1500,
)

# The v1 benchmark (docs/benchmark.md): the same envs with success that means stability,
# termination at a physical limit and task ranges with headroom (hexapod_envs.benchmark).
from .benchmark import V1_KWARGS as _V1_KWARGS  # noqa: E402

for _id, _kwargs in _V1_KWARGS.items():
    _v0 = gymnasium.spec(_id.replace("-v1", "-v0"))
    register(
        id=_id,
        entry_point=_v0.entry_point,
        max_episode_steps=_v0.max_episode_steps,
        vector_entry_point=_v0.vector_entry_point,
        kwargs=dict(_kwargs),
    )
