"""One closed-form check record, shared by every backend's validation (``tribodem validate``)."""

from __future__ import annotations

from typing import Any


def check(name: str, value: float, reference: float, tolerance: float,
          absolute: bool = False) -> dict[str, Any]:
    """``{"name", "value", "reference", "error", "tolerance", "pass"}``; the error is relative
    unless ``absolute`` (then in the value's unit)."""
    err = abs(value - reference) if absolute else abs(value - reference) / abs(reference)
    return {"name": name, "value": float(value), "reference": float(reference),
            "error": float(err), "tolerance": float(tolerance), "pass": bool(err <= tolerance)}
