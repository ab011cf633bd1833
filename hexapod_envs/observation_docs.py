"""The observation layout of every registered env, as a Markdown page (``docs/observations.md``).

Generated from each env's ``observation_structure`` (name -> slice of the flat Box), once per
action mode, so the page cannot drift from the code:
``tests/hexapod_envs/envs/test_observation_docs.py`` compares it with a fresh rendering.
Regenerate with::

    python -m hexapod_envs.observation_docs > docs/observations.md
"""

from __future__ import annotations

import sys

import gymnasium as gym

ENV_IDS = (
    "HexapodCliffWalk-v0",
    "HexapodStewartTilt-v0",
    "HexapodIrregularTerrain-v0",
    "HexapodDitchCrossing-v0",
)


def _action_modes(env: gym.Env) -> tuple[str, ...]:
    """The ACTION_MODES declared by the env's module or the module of one of its bases."""
    for klass in type(env.unwrapped).__mro__:
        modes = getattr(sys.modules.get(klass.__module__), "ACTION_MODES", None)
        if modes:
            return tuple(modes)
    return (env.unwrapped.action_mode,)


def render() -> str:
    """The whole page (default kwargs of each env, every action mode)."""
    import hexapod_envs  # noqa: F401  (registers the ids)

    lines = [
        "# Observation layouts",
        "",
        "Every env's observation is one flat `Box`; `env.unwrapped.observation_structure` maps "
        "each named piece to its slice, so code addresses pieces by name:",
        "`obs[env.unwrapped.observation_structure['fasm_margin_deg']]`.",
        "This page is generated from that mapping (`python -m hexapod_envs.observation_docs`); "
        "units and meanings are in each env module's docstring.",
        "",
    ]
    for env_id in ENV_IDS:
        probe = gym.make(env_id)
        modes = _action_modes(probe)
        probe.close()
        lines += [f"## {env_id}", ""]
        for mode in modes:
            env = gym.make(env_id, action_mode=mode)
            structure = env.unwrapped.observation_structure
            size = env.observation_space.shape[0]
            low, high = env.action_space.low.min(), env.action_space.high.max()
            lines += [
                f'### action_mode="{mode}": observation size {size}, '
                f"action shape {env.action_space.shape} in [{low:g}, {high:g}]",
                "",
                "| piece | indices | size |",
                "|---|---|---|",
            ]
            for name, piece in structure.items():
                n = piece.stop - piece.start
                lines.append(f"| `{name}` | {piece.start}–{piece.stop - 1} | {n} |")
            lines.append("")
            env.close()
    return "\n".join(lines)


if __name__ == "__main__":
    sys.stdout.write(render())
