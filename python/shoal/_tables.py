"""Column buffers from the native module, wrapped into ``pyarrow`` arrays without copying.

Each column arrives as ``(name, kind, length, null_count, buffers, extra)``: ``buffers`` are
Arrow's buffers for the type (validity bits first, ``None`` when no row is null, then offsets
and values in native byte order); ``extra`` is a ``dict`` column's categories or a ``list_str``
column's items ``(count, buffers)``.
"""

from __future__ import annotations

from typing import Any, List, Optional, Sequence, Tuple

import pyarrow as pa

Column = Tuple[str, str, int, int, List[Optional[bytes]], Any]

_PRIMITIVES = {
    "bool": pa.bool_(),
    "i64": pa.int64(),
    "u8": pa.uint8(),
    "u32": pa.uint32(),
    "u64": pa.uint64(),
    "f32": pa.float32(),
    "f64": pa.float64(),
}


def _buffers(raw: Sequence[Optional[bytes]]) -> List[Optional[pa.Buffer]]:
    return [None if b is None else pa.py_buffer(b) for b in raw]


def column_array(column: Column) -> pa.Array:
    """One column as a ``pyarrow`` array."""
    name, kind, length, nulls, raw, extra = column
    buffers = _buffers(raw)
    if kind in _PRIMITIVES:
        return pa.Array.from_buffers(_PRIMITIVES[kind], length, buffers, nulls)
    if kind == "str":
        return pa.Array.from_buffers(pa.string(), length, buffers, nulls)
    if kind == "dict":
        indices = pa.Array.from_buffers(pa.int32(), length, [None, buffers[1]], 0)
        return pa.DictionaryArray.from_arrays(indices, pa.array(extra, pa.string()))
    if kind == "list_str":
        items, item_buffers = extra
        child = pa.Array.from_buffers(pa.string(), items, _buffers(item_buffers), 0)
        return pa.Array.from_buffers(
            pa.list_(pa.string()), length, buffers, nulls, children=[child]
        )
    raise ValueError(f"column {name!r}: unknown kind {kind!r}")


def table(columns: Sequence[Column]) -> pa.Table:
    """Columns as a ``pyarrow.Table``, in the order given."""
    return pa.table({c[0]: column_array(c) for c in columns})
