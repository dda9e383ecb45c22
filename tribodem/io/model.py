"""The strict base of every config model: an unknown key is refused, and so are values that
would pass a lax reading but mean nothing (``inf`` or ``nan`` for a number, ``true`` for a
number)."""

from __future__ import annotations

import types
import typing
from typing import Any

from pydantic import BaseModel, ConfigDict, ValidationInfo, field_validator


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
