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


def _layouts(env_id: str) -> dict[str, tuple]:
    """Action mode -> (observation structure, action shape, low, high) of `env_id`."""
    probe = gym.make(env_id)
    modes = _action_modes(probe)
    probe.close()
    found = {}
    for mode in modes:
        env = gym.make(env_id, action_mode=mode)
        space = env.action_space
        found[mode] = (
            dict(env.unwrapped.observation_structure),
            space.shape,
            float(space.low.min()),
            float(space.high.max()),
        )
        env.close()
    return found


def render() -> str:
    """The whole page (default kwargs of each env, every action mode; a ``-v1`` id with the
    same layouts as its ``-v0`` id is named in the ``-v0`` section, else gets its own)."""
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
        layouts = _layouts(env_id)
        v1 = env_id.removesuffix("-v0") + "-v1"
        v1_layouts = _layouts(v1) if v1 in gym.registry else None
        if v1_layouts == layouts:
            sections = [(f"{env_id} and {v1}", layouts)]
        else:
            sections = [(env_id, layouts)] + ([(v1, v1_layouts)] if v1_layouts else [])
        for title, found in sections:
            lines += [f"## {title}", ""]
            for mode, (structure, shape, low, high) in found.items():
                size = max(piece.stop for piece in structure.values())
                lines += [
                    f'### action_mode="{mode}": observation size {size}, '
                    f"action shape {shape} in [{low:g}, {high:g}]",
                    "",
                    "| piece | indices | size |",
                    "|---|---|---|",
                ]
                for name, piece in structure.items():
                    n = piece.stop - piece.start
                    lines.append(f"| `{name}` | {piece.start}–{piece.stop - 1} | {n} |")
                lines.append("")
    return "\n".join(lines)


if __name__ == "__main__":
    sys.stdout.write(render())
