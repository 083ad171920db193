"""Decodes many payloads of one message type at once with numpy.

Decoding message by message with lcm-gen's classes and building the tables
from those objects took 5.8 s for a 40 s run (280 000 messages); this takes
under a second (docs/operations.md, "Logs in Python"). One message (the
template) is walked field by field to find where each value sits; that layout
is a numpy structured dtype (big-endian, explicit offsets) which decodes every
payload of the same length in one call. A layout holds for another payload
when the values that shape it (variable array lengths, string lengths) are
the template's; payloads where they differ get a template of their own. Each
template is also decoded with lcm-gen's class and must agree: the generated
code stays the reference.
"""
from dataclasses import dataclass
import math

import numpy as np

from .lcm_types import INTEGERS, PRIMITIVES


@dataclass
class _Piece:
    field: int  # index in MessageType.fields
    first: int  # flat index of its first element within the field
    count: int  # elements (1 for a scalar or a string)
    dtype: object  # numpy format; None: an empty string
    offset: int
    string: bool
    array: bool  # an array field (even of one element): its values come as (rows, count)


def _layout(mtype, payload):
    """(pieces, checks) of `payload`; checks: (offset, format, value) that
    another payload must share for the same layout. ValueError if the payload
    does not fit the type."""
    dim_fields = {d for f in mtype.fields for d in f.dims if isinstance(d, str)}
    values, pieces, checks = {}, [], []
    offset = 8  # the fingerprint
    for index, field in enumerate(mtype.fields):
        count = math.prod(d if isinstance(d, int) else values[d] for d in field.dims)
        if count < 0:
            raise ValueError(f"negative length of {field.name}")
        if field.type == "string":
            for element in range(count):
                size = _read(payload, ">u4", offset)  # counts the final NUL
                if size < 1:
                    raise ValueError(f"bad string length in {field.name}")
                checks.append((offset, ">u4", size))
                text_dtype = f"S{size - 1}" if size > 1 else None
                pieces.append(_Piece(index, element, 1, text_dtype, offset + 4, True, False))
                offset += 4 + size
            continue
        if field.type not in PRIMITIVES:
            raise NotImplementedError(f"{mtype.name}.{field.name}: nested type {field.type}")
        code = PRIMITIVES[field.type]
        if field.name in dim_fields and field.type in INTEGERS and not field.dims:
            values[field.name] = _read(payload, code, offset)
            checks.append((offset, code, values[field.name]))
        pieces.append(_Piece(index, 0, count, code, offset, False, bool(field.dims)))
        offset += np.dtype(code).itemsize * count
    if offset != len(payload):
        raise ValueError(f"payload of {len(payload)} bytes, {mtype.name} layout needs {offset}")
    return pieces, checks


def _read(payload, code, offset):
    if offset + np.dtype(code).itemsize > len(payload):
        raise ValueError("payload too short for its type")
    return int(np.frombuffer(payload, code, 1, offset)[0])


def _dtype(pieces, checks, itemsize):
    names, formats, offsets = [], [], []
    for i, piece in enumerate(pieces):
        if piece.dtype is None or piece.count == 0:
            continue
        names.append(f"p{i}")
        formats.append((piece.dtype, (piece.count,)) if piece.array else piece.dtype)
        offsets.append(piece.offset)
    for i, (offset, code, _) in enumerate(checks):
        names.append(f"c{i}")
        formats.append(code)
        offsets.append(offset)
    return np.dtype({"names": names, "formats": formats, "offsets": offsets,
                     "itemsize": itemsize})


def _columns(mtype, pieces, table):
    """{(field index, flat element index): 1-D native-endian array} of a decoded table."""
    columns = {}
    for i, piece in enumerate(pieces):
        field = mtype.fields[piece.field]
        if piece.string:
            if piece.dtype is None:
                columns[(piece.field, piece.first)] = np.full(len(table), "", dtype=object)
            else:
                columns[(piece.field, piece.first)] = _strings(table[f"p{i}"])
            continue
        if piece.count == 0:
            continue
        values = table[f"p{i}"]
        values = values.astype(values.dtype.newbyteorder("="))
        if field.type == "boolean":
            values = values != 0
        if values.ndim == 1:
            columns[(piece.field, 0)] = values
        else:
            for element in range(piece.count):
                columns[(piece.field, element)] = values[:, element]
    return columns


def _strings(raw):
    # Few distinct values per column: decode each once.
    unique, inverse = np.unique(raw, return_inverse=True)
    decoded = np.empty(len(unique), dtype=object)
    decoded[:] = [u.decode("utf-8", "replace") for u in unique]
    return decoded[inverse]


def _flatten(value):
    if isinstance(value, (bytes, bytearray)):  # lcm-gen's decoding of a byte array
        return list(value)
    if isinstance(value, (list, tuple)):
        return [x for v in value for x in _flatten(v)]
    return [value]


def _check_against_generated(mtype, payload, columns):
    reference = mtype.generated.decode(payload)
    for index, field in enumerate(mtype.fields):
        expected = _flatten(getattr(reference, field.name))
        if not field.dims:
            expected = expected[:1]
        for element, value in enumerate(expected):
            got = columns.get((index, element))
            got = got[0] if got is not None else None
            same = got == value or (isinstance(value, float) and math.isnan(value)
                                    and got is not None and np.isnan(got))
            if not same:
                raise RuntimeError(
                    f"{mtype.name}.{field.name}[{element}]: layout gives {got!r}, lcm-gen's "
                    f"decoder {value!r}: stewart_types.txt and the generated modules differ "
                    "(rebuild the target stewart_lcmtypes_python)")


def decode_payloads(mtype, data, offsets, length):
    """Decodes the payloads of `length` bytes at `offsets` in `data`, all of
    type `mtype`. Yields (rows, columns) per layout: rows index `offsets`,
    columns as _columns() gives them, or None for a payload that does not
    decode as the type."""
    raw = np.frombuffer(b"".join(data[o:o + length] for o in offsets.tolist()), dtype=np.uint8)
    raw = raw.reshape(len(offsets), length)
    remaining = np.arange(len(offsets))
    while remaining.size:
        template = raw[remaining[0]].tobytes()
        try:
            pieces, checks = _layout(mtype, template)
        except ValueError:
            yield remaining[:1], None
            remaining = remaining[1:]
            continue
        rows = raw if remaining.size == len(raw) else raw[remaining]  # no copy when one layout
        table = rows.view(_dtype(pieces, checks, length))[:, 0]
        same = np.ones(len(table), dtype=bool)
        for i, (_, _, value) in enumerate(checks):
            same &= table[f"c{i}"] == value
        columns = _columns(mtype, pieces, table[same])
        _check_against_generated(mtype, template, columns)
        yield remaining[same], columns
        remaining = remaining[~same]
