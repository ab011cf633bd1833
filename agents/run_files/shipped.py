"""Where the shipped configs (``configs/*.yaml``) and models (``models/<env id>/<agent>/``) are.

The repository root holds the one copy of both. A source checkout (and an editable install,
``pip install -e .``) reads them there; a wheel carries them as package data of `agents`
(``agents/_shipped/configs``, ``agents/_shipped/models``, copied by ``setup.py`` at build
time), so that an installed ``hexapod-evaluate`` works from any folder.

A relative path that begins with ``configs/`` or ``models/`` (``--config configs/x.yaml``,
``ppo:models/{env_id}/ppo``) is looked up in the working directory first, so your own files of
that name win, and otherwise in the shipped data.
"""

from __future__ import annotations

from pathlib import Path

SHIPPED_DIRS = ("configs", "models")
"""The top-level folders of the repository that the wheel carries."""

PACKAGED = Path(__file__).resolve().parents[1] / "_shipped"
"""Their copy inside an installed wheel (absent in a source checkout)."""

CHECKOUT = Path(__file__).resolve().parents[2]
"""The repository root of a source checkout (or the site-packages folder of an install)."""


def shipped_root() -> Path:
    """The folder that holds the shipped ``configs/`` and ``models/``."""
    return PACKAGED if (PACKAGED / "configs").is_dir() else CHECKOUT


def shipped_path(*parts: str) -> Path:
    """A path under the shipped data, e.g. ``shipped_path("configs", "evaluate_default.yaml")``."""
    return shipped_root().joinpath(*parts)


def resolve_shipped(path: str | Path) -> Path:
    """`path` itself unless it is a relative ``configs/...`` or ``models/...`` path that does not
    exist from the working directory but does in the shipped data: then that shipped file."""
    path = Path(path)
    if path.is_absolute() or path.exists() or not path.parts or path.parts[0] not in SHIPPED_DIRS:
        return path
    shipped = shipped_root() / path
    return shipped if shipped.exists() else path
