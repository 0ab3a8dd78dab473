"""The batch manifest: one JSON object per line (``manifest.jsonl`` in the output folder), appended per item.

Each finished item appends one record (see ``docs/batch.md`` for every field): ``output`` (the key: the
item's ``.npz`` path relative to the output folder), ``input``, ``task``, ``status`` (``done`` | ``failed`` |
``cancelled``), ``input_sha256`` (content hash of the input file), ``params_sha256`` (hash of the task and its
options), ``options``, ``seconds`` (``read``, ``compute``, ``write``, ``total``), ``counts`` (input sizes),
``topology`` (an input mesh's ``open``, ``non_manifold``, ``oriented``, ``components``, ``degenerate_faces``),
``arrays`` (output shapes), ``mesh`` (the mesh file of ``surface_format``), ``error``, ``attempts``, ``worker``,
``run`` and ``time``. The last record of an
item is its state; a line cut short by a hard kill is ignored when reading. Lines are written whole, flushed
and fsync'ed, so the manifest never claims an output that is not on disk.
"""

from __future__ import annotations

import hashlib
import json
import os

MANIFEST_NAME = "manifest.jsonl"
CHUNK = 1 << 20


def file_sha256(path) -> str:
    """Hex SHA-256 of a file's bytes (read in 1 MiB chunks)."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(CHUNK), b""):
            h.update(block)
    return h.hexdigest()


def params_sha256(task: str, options: dict) -> str:
    """Hash of a task and its validated options: an output is reused only when these match."""
    text = json.dumps({"task": task, "options": options}, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def read_manifest(path) -> dict:
    """The last record of every item (key: ``output``) of a manifest file; {} when it does not exist."""
    state = {}
    if not os.path.exists(path):
        return state
    with open(path, encoding="utf-8", errors="replace") as fh:
        for line in fh:
            try:
                rec = json.loads(line)
            except json.JSONDecodeError:
                continue  # a line cut short by a hard kill
            if isinstance(rec, dict) and isinstance(rec.get("output"), str):
                state[rec["output"]] = rec
    return state


class ManifestWriter:
    """Appends records to a manifest, one whole line per record, flushed and fsync'ed."""

    def __init__(self, path):
        self.path = os.fspath(path)
        self._fh = open(self.path, "a", encoding="utf-8")
        if self._fh.tell() > 0:  # a previous run killed mid-line: start on a fresh line
            with open(self.path, "rb") as fh:
                fh.seek(-1, os.SEEK_END)
                if fh.read(1) != b"\n":
                    self._fh.write("\n")

    def write(self, record: dict) -> None:
        self._fh.write(json.dumps(record, sort_keys=True, default=str) + "\n")
        self._fh.flush()
        os.fsync(self._fh.fileno())

    def close(self) -> None:
        self._fh.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
