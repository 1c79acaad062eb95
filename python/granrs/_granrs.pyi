"""Type stubs of the compiled core (rust/python/mod.rs). Use the public API in granrs instead."""

from typing import Any

__version__: str
EFFECTS: list[str]
RECORDS: list[str]

def simulate(scene: dict[str, Any]) -> dict[str, Any]:
    """Run one scene dict (from Scene.to_dict()); return the raw results dict."""

def validate(scene: dict[str, Any]) -> None:
    """Validate a scene dict; raise the typed granrs error naming the first bad field."""

def leg_segments(scene: dict[str, Any]) -> list[dict[str, Any]]:
    """The leg's segments (name, mass, length, com, inertia) for a leg scene dict."""
