"""The strict base of every config model: an unknown key is refused, and so are values that
would pass a lax reading but mean nothing (``inf`` or ``nan`` for a number, ``true`` for a
number). The top model of a command's config (:class:`PhysicalConfig`) also refuses a
physical input outside the range of real materials and rigs its field declares
(:func:`physical`), unless ``allow_unphysical = true``."""

from __future__ import annotations

import types
import typing
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, ValidationInfo, field_validator, model_validator
from pydantic.fields import FieldInfo
from pydantic_core import InitErrorDetails, PydanticCustomError, ValidationError


def _number_field(annotation: Any) -> bool:
    """Whether a field annotated ``annotation`` takes numbers (int or float) and not
    booleans: ``int``, ``float``, or a union holding one of them and not ``bool``."""
    if annotation in (int, float):
        return True
    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        args = typing.get_args(annotation)
        return bool not in args and (int in args or float in args)
    return False


class StrictModel(BaseModel):
    """A pydantic model that refuses keys it does not declare (a typo is an error, not a
    silently ignored setting), infinite or NaN numbers, and a boolean where a number is
    expected (pydantic's lax mode would read ``true`` as 1)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    @field_validator("*", mode="before")
    @classmethod
    def _no_bool_for_number(cls, v: Any, info: ValidationInfo) -> Any:
        if isinstance(v, bool) and info.field_name is not None:
            field = cls.model_fields.get(info.field_name)
            if field is not None and _number_field(field.annotation):
                raise ValueError(f"a number, not {str(v).lower()}")
        return v


#: The key of a field's ``json_schema_extra`` that holds its physical range ``(lo, hi)``
#: (:func:`physical`): the range of real materials and rigs, checked by
#: :class:`PhysicalConfig` unless ``allow_unphysical = true``.
PHYSICAL = "physical"

#: The key of a field's ``json_schema_extra`` that holds the unit of its physical range.
UNIT = "unit"

#: The sentence every physically bounded field's description ends with.
UNPHYSICAL_HINT = "beyond it only with allow_unphysical = true"


def _num(v: float) -> str:
    """A bound as the message and the description write it (``1e+06`` as ``1e6``)."""
    text = f"{v:g}"
    mant, e, exp = text.partition("e")
    return f"{mant}e{int(exp)}" if e else text


def range_text(lo: float, hi: float, unit: str = "") -> str:
    """``lo..hi unit``, as descriptions and messages state a physical range."""
    return f"{_num(lo)}..{_num(hi)}{f' {unit}' if unit else ''}"


def physical(lo: float, hi: float, unit: str = "", description: str = "") -> dict[str, Any]:
    """The keyword arguments of ``Field`` for a field bounded by the range of real
    materials and rigs, declared once: ``json_schema_extra={"physical": (lo, hi)}`` (what
    :class:`PhysicalConfig` checks and the config reference reads) and ``description``
    with the range stated at its end."""
    text = f"physical range {range_text(lo, hi, unit)} ({UNPHYSICAL_HINT})"
    extra: dict[str, Any] = {PHYSICAL: (lo, hi)}
    if unit:
        extra[UNIT] = unit
    return {"description": f"{description}; {text}" if description else text,
            "json_schema_extra": extra}


def physical_range(field: FieldInfo) -> tuple[float, float] | None:
    """The ``(lo, hi)`` a field declares with :func:`physical`, else None."""
    extra = field.json_schema_extra
    if isinstance(extra, dict):
        rng = extra.get(PHYSICAL)
        if isinstance(rng, tuple | list) and len(rng) == 2:
            return float(rng[0]), float(rng[1])
    return None


def physical_unit(field: FieldInfo) -> str:
    """The unit of the physical range a field declares (empty: none, or a ratio)."""
    extra = field.json_schema_extra
    return str(extra.get(UNIT, "")) if isinstance(extra, dict) else ""


def unphysical_fields(model: BaseModel, prefix: str = ""
                      ) -> list[tuple[str, Any, str]]:
    """(dotted field, value, its range as text) of every field of ``model`` and of its
    nested models whose value lies outside the physical range it declares
    (:func:`physical`; a field left None is not checked; a tuple of numbers is checked
    element by element)."""
    out: list[tuple[str, Any, str]] = []
    for name, field in type(model).model_fields.items():
        v = getattr(model, name, None)
        rng = physical_range(field)
        if rng is not None and v is not None:
            lo, hi = rng
            values = v if isinstance(v, tuple | list) else (v,)
            if any(isinstance(x, int | float) and not lo <= x <= hi for x in values):
                out.append((f"{prefix}{name}", v, range_text(lo, hi, physical_unit(field))))
        elif isinstance(v, BaseModel):
            out += unphysical_fields(v, f"{prefix}{name}.")
    return out


def physical_ranges(model: type[BaseModel], prefix: str = ""
                    ) -> dict[str, tuple[float, float]]:
    """Dotted field -> ``(lo, hi)`` of every physically bounded field of ``model`` and of
    its nested models (for the config reference and the tests)."""
    out: dict[str, tuple[float, float]] = {}
    for name, field in model.model_fields.items():
        rng = physical_range(field)
        sub = field.annotation
        if rng is not None:
            out[f"{prefix}{name}"] = rng
        elif isinstance(sub, type) and issubclass(sub, BaseModel):
            out |= physical_ranges(sub, f"{prefix}{name}.")
    return out


class PhysicalConfig(StrictModel):
    """The top model of a command's config: every field declared with :func:`physical` (in
    it or in its tables) must lie in its physical range, the range of real materials and
    rigs, unless ``allow_unphysical = true``. A value outside is refused naming the field,
    the value and the range (one line per field; the CLI: exit 2)."""

    allow_unphysical: bool = Field(
        False, strict=True, description="accept values outside the physical ranges of "
        "real materials and rigs that the fields state (for a study that needs them; the "
        "memory checks still apply)")

    @model_validator(mode="after")
    def _physical(self) -> Any:
        if self.allow_unphysical:
            return self
        bad = unphysical_fields(self)
        if bad:
            raise ValidationError.from_exception_data(type(self).__name__, [
                InitErrorDetails(
                    type=PydanticCustomError(
                        "unphysical", f"outside the range of real materials and rigs; "
                        f"allowed: {rng}, or allow_unphysical = true (top level of the "
                        "config) for a study that needs it"),
                    loc=tuple(name.split(".")), input=value)
                for name, value, rng in bad])
        return self
