"""Reading the project's TOML files (airframe, aero model, flight plan) with one-line errors."""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

from .errors import InputError

__all__ = ["read_toml"]


def read_toml(path: str | Path, what: str) -> dict[str, Any]:
    """Parse a TOML file.

    Args:
        path: the file.
        what: what it is, for messages (``"airframe file"``, ``"model file"``, ``"plan file"``).

    Returns:
        The parsed document.

    Raises:
        InputError: the file is missing or unreadable, not UTF-8, or not valid TOML; the message
            names the file, e.g. ``t28.toml: not valid TOML (Expected '=' ... (line 3, column 7))``.
    """
    p = Path(path)
    try:
        return tomllib.loads(p.read_bytes().decode("utf-8"))
    except FileNotFoundError:
        raise InputError(f"{p}: {what} not found") from None
    except (OSError, UnicodeDecodeError) as e:
        raise InputError(f"{p}: cannot read {what} ({e.__class__.__name__})") from None
    except tomllib.TOMLDecodeError as e:
        raise InputError(f"{p}: not valid TOML ({e})") from None
