"""Typed configs from YAML: ``yaml.safe_load`` into nested dataclasses, strictly.

- An unknown key is an error that names it (with its dotted path), suggests the closest valid key
  and lists every valid key at that level.
- Values are checked against the field's type (bool, int, float, str, Literal choices, lists,
  dicts, Optional, nested dataclasses); a field may carry its own parser in
  ``field(metadata={"parse": fn})`` (used for schedules).
- Command-line overrides ``key.sub=value`` are applied to the raw mapping before validation, so
  they obey exactly the same rules; the value is read as YAML (``true``, ``[64, 64]``, ``1e-4``).

PyYAML reads ``3e-4`` (no dot) as a string; float fields accept such strings, so configs can be
written the natural way.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import types
import typing
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, Literal, TypeVar, get_args, get_origin, get_type_hints

import yaml

from .errors import ConfigError

T = TypeVar("T")


def load_yaml(path: str | Path) -> dict[str, Any]:
    """Read a YAML mapping with ``yaml.safe_load``; clear errors for missing files and bad YAML."""
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"config file not found: {path}")
    try:
        data = yaml.safe_load(path.read_text())
    except yaml.YAMLError as exc:
        raise ConfigError(f"{path} is not valid YAML: {exc}") from None
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise ConfigError(f"{path} must hold a mapping at the top level, got {type(data).__name__}")
    return data


def parse_float(value: Any, where: str) -> float:
    """A float from a YAML number or a numeric string such as ``"3e-4"`` (not a bool)."""
    if isinstance(value, bool):
        raise ConfigError(f"{where}: expected a number, got {value!r}")
    if isinstance(value, int | float):
        return float(value)
    if isinstance(value, str) and "_" not in value:  # float() reads "1e-4_2" as 1e-42
        try:
            return float(value)
        except ValueError:
            pass
    raise ConfigError(f"{where}: expected a number, got {value!r}")


def _describe(tp: Any) -> str:
    if tp is type(None):
        return "null"
    if get_origin(tp) is Literal:
        return " | ".join(repr(a) for a in get_args(tp))
    if get_origin(tp) in (typing.Union, types.UnionType):
        return " | ".join(_describe(a) for a in get_args(tp))
    origin = get_origin(tp)
    if origin is not None:
        args = ", ".join(_describe(a) for a in get_args(tp))
        return f"{origin.__name__}[{args}]"
    return getattr(tp, "__name__", str(tp))


def _convert(tp: Any, value: Any, where: str) -> Any:
    """Check/convert `value` to type `tp`; raise ConfigError naming `where` on mismatch."""
    origin = get_origin(tp)
    if tp is Any:
        return value
    if tp is type(None):
        if value is None:
            return None
        raise ConfigError(f"{where}: expected null, got {value!r}")
    if origin is Literal:
        choices = get_args(tp)
        if value in choices:
            return value
        raise ConfigError(f"{where}: {value!r} is not a valid choice; valid: {list(choices)}")
    if origin in (typing.Union, types.UnionType):
        args = get_args(tp)
        if value is None and type(None) in args:
            return None
        options = [arg for arg in args if arg is not type(None)]
        errors = []
        for arg in options:
            try:
                return _convert(arg, value, where)
            except ConfigError as exc:
                errors.append(str(exc))
        if len(options) == 1 and dataclasses.is_dataclass(options[0]):
            raise ConfigError(errors[0])  # an optional section: its own error says what is wrong
        raise ConfigError(f"{where}: expected {_describe(tp)}, got {value!r}")
    if dataclasses.is_dataclass(tp):
        return from_mapping(tp, value, where)
    if tp is bool:
        if isinstance(value, bool):
            return value
        raise ConfigError(f"{where}: expected true or false, got {value!r}")
    if tp is int:
        if isinstance(value, bool):
            raise ConfigError(f"{where}: expected an integer, got {value!r}")
        if isinstance(value, int):
            return value
        if isinstance(value, float) and value.is_integer():
            return int(value)
        if isinstance(value, str):
            try:
                number = float(value)
            except ValueError:
                number = math.nan
            if number.is_integer():
                return int(number)
        raise ConfigError(f"{where}: expected an integer, got {value!r}")
    if tp is float:
        return parse_float(value, where)
    if tp is str:
        if isinstance(value, str):
            return value
        raise ConfigError(f"{where}: expected a string, got {value!r}")
    if origin in (list, Sequence, tuple):
        if not isinstance(value, list | tuple):
            raise ConfigError(f"{where}: expected a list, got {value!r}")
        (item_type, *_) = get_args(tp) or (Any,)
        return [_convert(item_type, v, f"{where}[{i}]") for i, v in enumerate(value)]
    if origin in (dict, Mapping):
        if not isinstance(value, dict):
            raise ConfigError(f"{where}: expected a mapping, got {value!r}")
        key_type, value_type = get_args(tp) or (str, Any)
        return {
            _convert(key_type, k, f"{where}"): _convert(value_type, v, f"{where}.{k}")
            for k, v in value.items()
        }
    raise TypeError(f"configtools cannot check fields of type {tp!r} ({where})")


def unknown_key_message(key: str, where: str, valid: Sequence[str]) -> str:
    """E.g. "unknown key 'ppo.lerning_rate' (did you mean 'learning_rate'?); valid keys in
    'ppo': ..."."""
    dotted = f"{where}.{key}" if where else key
    close = difflib.get_close_matches(key, valid, n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    level = f"in {where!r}" if where else "at the top level"
    return f"unknown key {dotted!r}{hint}; valid keys {level}: {', '.join(sorted(valid))}"


def from_mapping(cls: type[T], data: Any, where: str = "") -> T:
    """Build dataclass `cls` from a mapping, recursively; strict about keys and types."""
    label = where or "config"
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise ConfigError(f"{label}: expected a mapping, got {data!r}")
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}
    hints = get_type_hints(cls)
    for key in data:
        if key not in fields:
            raise ConfigError(unknown_key_message(str(key), where, list(fields)))
    kwargs = {}
    for name, fld in fields.items():
        path = f"{where}.{name}" if where else name
        if name not in data:
            no_default = fld.default is dataclasses.MISSING
            if no_default and fld.default_factory is dataclasses.MISSING:
                raise ConfigError(f"missing required key {path!r}")
            continue
        parser = fld.metadata.get("parse")
        value = data[name]
        kwargs[name] = parser(value, path) if parser else _convert(hints[name], value, path)
    try:
        return cls(**kwargs)
    except (ValueError, TypeError) as exc:  # __post_init__ checks
        raise ConfigError(f"{label}: {exc}") from None


def to_mapping(obj: Any) -> Any:
    """Dataclass (tree) -> plain YAML-safe data; objects with ``to_yaml()`` dump themselves."""
    if hasattr(obj, "to_yaml"):
        return obj.to_yaml()
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: to_mapping(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    if isinstance(obj, dict):
        return {k: to_mapping(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [to_mapping(v) for v in obj]
    return obj


def dump_yaml(obj: Any) -> str:
    return yaml.safe_dump(to_mapping(obj), sort_keys=False, default_flow_style=None)


def parse_override(text: str) -> tuple[list[str], Any]:
    """``"ppo.learning_rate=1e-4"`` -> (["ppo", "learning_rate"], "1e-4"); value read as YAML."""
    key, sep, raw = text.partition("=")
    key = key.strip()
    if not sep or not key or any(not part for part in key.split(".")):
        raise ConfigError(f"override {text!r} must look like key.subkey=value")
    try:
        value = yaml.safe_load(raw) if raw.strip() else None
    except yaml.YAMLError as exc:
        hint = ""
        if any(c in raw for c in "{}"):  # e.g. policies=[ppo:models/{env_id}/ppo]
            hint = (
                "; if the { } are meant as text, quote the string (YAML reads { } as a "
                "mapping), e.g. --set 'policies=[\"ppo:models/{env_id}/ppo\", zero]'"
            )
        raise ConfigError(f"override {text!r}: value is not valid YAML{hint}: {exc}") from None
    return key.split("."), value


def apply_overrides(data: dict[str, Any], overrides: Sequence[str]) -> dict[str, Any]:
    """Return a copy of `data` with each ``a.b.c=value`` override set (creating levels)."""
    import copy

    result = copy.deepcopy(data)
    for text in overrides:
        path, value = parse_override(text)
        node = result
        for i, part in enumerate(path[:-1]):
            child = node.get(part)
            if child is None:
                child = node[part] = {}
            elif not isinstance(child, dict):
                dotted = ".".join(path[: i + 1])
                raise ConfigError(f"override {text!r}: {dotted!r} is a value, not a mapping")
            node = child
        node[path[-1]] = value
    return result
