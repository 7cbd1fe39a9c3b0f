"""Tables for notebooks: pandas DataFrames of results (pandas is imported only here).

Shared by every layer that has a ``to_pandas()`` (the model's Trajectory, the analyses'
results), so it sits with the other modules every layer may use (errors, progress,
parallel), below the model."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from .errors import MissingExtraError, UsageError

#: No public names: the results' ``to_pandas()`` methods are the API.
__all__: list[str] = []

if TYPE_CHECKING:
    import pandas


def _show(value: Any) -> str:
    # This module is below the model (it may not import dumbbell.model.args): a short repr.
    text = " ".join(repr(value).split())
    return text if len(text) <= 60 else text[:57] + "..."


def _pandas_module(what: str = "to_pandas()") -> Any:
    """The pandas module, or a MissingExtraError naming the extra that installs it."""
    try:
        import pandas
    except ImportError:
        raise MissingExtraError(f"{what} needs pandas: pip install 'dumbbell[pandas]'") from None
    return pandas


def data_frame(columns: Mapping[str, Sequence[Any]], index: str | None = None,
               units: Mapping[str, str] | None = None) -> pandas.DataFrame:
    """A DataFrame of ``columns`` in their order, ``index`` (a column name) as its index, and
    the unit of every column (index included) in ``df.attrs["units"]``."""
    if not isinstance(columns, Mapping):
        raise UsageError(f"columns = {_show(columns)}: must be a dict of column name to "
                         "values", param="columns")
    if index is not None and (not isinstance(index, str) or index not in columns):
        raise UsageError(f"index = {_show(index)}: must be one of the columns or None",
                         param="index")
    if units is not None and not isinstance(units, Mapping):
        raise UsageError(f"units = {_show(units)}: must be a dict of column name to unit, or "
                         "None", param="units")
    pd = _pandas_module()
    df = pd.DataFrame({name: columns[name] for name in columns})
    if index is not None:
        df = df.set_index(index)
    df.attrs["units"] = dict(units or {})
    return df
