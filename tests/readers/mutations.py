"""Mutations of real input files for the readers' fuzz suite.

Each mutation takes a ``random.Random`` and the content of a file and returns hostile content
of the same kind: bytes (truncated, flipped), documents (a value replaced by a wrong type, NaN,
a huge number, an empty list; a key dropped), Arrow tables (a column replaced, emptied, made
non-monotonic), TFRecords (payloads mutated with valid checksums, huge lengths).
"""

from __future__ import annotations

import io
import json
import math
import pickle
import random
import struct
import xml.etree.ElementTree as ET
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.feather as feather
import pyarrow.parquet as pq

HOSTILE: tuple[Any, ...] = (
    math.nan,
    math.inf,
    -math.inf,
    2**31,
    2**63 - 1,
    -(2**40),
    -1,
    0,
    1e308,
    "",
    "x\x1b[2J<!--<script>",
    None,
    [],
    {},
    True,
    [1, 2, 3],
)
"""Values put in place of a file's values: wrong types, non-finite and huge numbers, empties."""


# ------------------------------------------------------------------ bytes
def truncate(rng: random.Random, data: bytes) -> bytes:
    """The first k bytes, k uniform in [0, len)."""
    return data[: rng.randrange(max(len(data), 1))]


def flip(rng: random.Random, data: bytes) -> bytes:
    """Up to 8 bytes replaced by random bytes."""
    out = bytearray(data)
    for _ in range(rng.randint(1, 8)):
        if out:
            out[rng.randrange(len(out))] = rng.randrange(256)
    return bytes(out)


def invalid_utf8(rng: random.Random, data: bytes) -> bytes:
    """A byte that is never valid UTF-8 put at a random place."""
    k = rng.randrange(max(len(data), 1))
    return data[:k] + b"\xff\xfe" + data[k + 1 :]


BYTE_MUTATIONS = (truncate, flip, invalid_utf8)


# ------------------------------------------------------------------ documents (JSON, pickles)
def _slots(tree: Any, out: list[tuple[Any, Any]]) -> list[tuple[Any, Any]]:
    """Every (container, key) of a nested document of dicts and lists."""
    items = tree.items() if isinstance(tree, dict) else enumerate(tree) if isinstance(tree, list) else ()
    for key, value in items:
        out.append((tree, key))
        _slots(value, out)
    return out


def _hostile_array(rng: random.Random, array: np.ndarray) -> Any:
    """An array with a hostile element, dtype or shape."""
    choice = rng.randrange(5)
    if choice == 0 and array.size and array.dtype.kind in "fiu":
        out = array.astype(np.float64).copy()
        out.flat[rng.randrange(array.size)] = rng.choice([math.nan, math.inf, 1e300, -1e300])
        return out.astype(array.dtype) if array.dtype.kind == "f" else out
    if choice == 1:
        return array[:0]
    if choice == 2:
        return array.reshape(-1)[: max(array.size // 2, 0)]
    if choice == 3:
        return array.astype(str) if array.dtype.kind != "O" else array
    return rng.choice(HOSTILE)


def mutate_document(rng: random.Random, tree: Any) -> Any:
    """The document with one value replaced by a hostile one, or one key dropped (in place)."""
    slots = _slots(tree, [])
    if not slots:
        return rng.choice(HOSTILE)
    container, key = rng.choice(slots)
    value = container[key]
    if isinstance(container, dict) and rng.random() < 0.2:
        del container[key]
    elif isinstance(value, np.ndarray):
        container[key] = _hostile_array(rng, value)
    else:
        container[key] = rng.choice(HOSTILE)
    return tree


def json_document(rng: random.Random, data: bytes) -> bytes:
    """A JSON file with one value mutated (NaN and infinities written as JSON5-style literals)."""
    return json.dumps(mutate_document(rng, json.loads(data))).encode()


def pickle_document(rng: random.Random, data: bytes) -> bytes:
    """A ScenarioNet pickle with one value mutated."""
    from scenegrep.readers.scenarionet import RestrictedUnpickler

    return pickle.dumps(mutate_document(rng, RestrictedUnpickler(io.BytesIO(data)).load()), protocol=4)


def xml_document(rng: random.Random, data: bytes) -> bytes:
    """An XML file with one attribute or text replaced by a hostile value, or one element dropped."""
    root = ET.fromstring(data)
    elements = list(root.iter())
    element = rng.choice(elements)
    if rng.random() < 0.2 and len(element):
        element.remove(rng.choice(list(element)))
    elif element.attrib and rng.random() < 0.5:
        element.set(rng.choice(list(element.attrib)), str(rng.choice(HOSTILE)))
    else:
        element.text = str(rng.choice(HOSTILE))
    return ET.tostring(root)


# ------------------------------------------------------------------ Arrow tables
def _hostile_column(rng: random.Random, column: pa.ChunkedArray) -> pa.Array:
    n = len(column)
    kind = rng.randrange(5)
    if kind == 0 and pa.types.is_floating(column.type):
        return pa.array(np.full(n, rng.choice([math.nan, math.inf, 1e300])), column.type)
    if kind == 1 and pa.types.is_integer(column.type):
        values = column.to_numpy().astype(np.int64)
        values[rng.randrange(n)] = rng.choice([2**31, 2**62, -1, -(2**40)])
        return pa.array(values).cast(column.type, safe=False)
    if kind == 2:
        return pc.take(column, pa.array(np.random.default_rng(rng.randrange(2**32)).permutation(n))).combine_chunks()
    if kind == 3:
        return pa.array(np.zeros(n, dtype=np.int64))
    return pa.nulls(n, column.type)


def mutate_table(rng: random.Random, table: pa.Table) -> pa.Table:
    """A table with a column replaced by a hostile one, dropped, or every row removed."""
    choice = rng.randrange(6)
    if choice == 0 or table.num_rows == 0:
        return table.slice(0, 0)
    name = rng.choice(table.column_names)
    if choice == 1:
        return table.drop_columns([name])
    column = _hostile_column(rng, table.column(name))
    return table.set_column(table.column_names.index(name), pa.field(name, column.type), column)


def _table_metadata(rng: random.Random, table: pa.Table) -> pa.Table:
    """The table with one value of its JSON schema metadata mutated."""
    metadata = dict(table.schema.metadata or {})
    key = rng.choice(list(metadata))
    try:
        document = json.loads(metadata[key])
    except ValueError:
        return table
    metadata[key] = json.dumps(mutate_document(rng, document)).encode()
    return table.replace_schema_metadata(metadata)


def parquet_table(rng: random.Random, data: bytes) -> bytes:
    """A Parquet file with its table (or its JSON metadata) mutated."""
    table = pq.read_table(io.BytesIO(data))
    mutation = _table_metadata if table.schema.metadata and rng.random() < 0.3 else mutate_table
    table = mutation(rng, table)
    out = io.BytesIO()
    pq.write_table(table, out)
    return out.getvalue()


def feather_table(rng: random.Random, data: bytes) -> bytes:
    """A Feather file with its table mutated."""
    out = io.BytesIO()
    feather.write_feather(mutate_table(rng, feather.read_table(io.BytesIO(data))), out)
    return out.getvalue()


# ------------------------------------------------------------------ TFRecords
def _records(data: bytes) -> list[bytes]:
    records, offset = [], 0
    while offset + 12 <= len(data):
        (length,) = struct.unpack_from("<Q", data, offset)
        records.append(data[offset + 12 : offset + 12 + length])
        offset += 12 + length + 4
    return records


def _frame(payload: bytes, length: int | None = None) -> bytes:
    from scenegrep.readers.tfrecord import masked_crc32c

    header = struct.pack("<Q", len(payload) if length is None else length)
    return header + struct.pack("<I", masked_crc32c(header)) + payload + struct.pack("<I", masked_crc32c(payload))


def tfrecord_payload(rng: random.Random, data: bytes) -> bytes:
    """A TFRecord file whose first record's payload is flipped or truncated, checksums valid."""
    records = _records(data)
    records[0] = rng.choice((flip, truncate))(rng, records[0])
    return b"".join(_frame(r) for r in records)


def tfrecord_length(rng: random.Random, data: bytes) -> bytes:
    """A TFRecord file whose first record claims a huge length (with a valid header checksum)."""
    records = _records(data)
    return _frame(records[0], rng.choice([2**31, 2**40, 2**63]))[: 12 + len(records[0])]


Mutation = Callable[[random.Random, bytes], bytes]


def mutate_file(path: Path, mutations: tuple[Mutation, ...], rng: random.Random) -> None:
    """Replace the file at ``path`` by one mutation (chosen by ``rng``) of its content; a mutation
    that cannot apply to this content (a truncated file is no longer a table) leaves bytes mutated."""
    data = path.read_bytes()
    mutation = rng.choice(mutations)
    try:
        path.write_bytes(mutation(rng, data))
    except (ValueError, KeyError, IndexError, TypeError, pa.ArrowException, ET.ParseError, pickle.PickleError):
        path.write_bytes(flip(rng, data))
