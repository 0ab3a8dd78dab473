"""How a valid value, argument or file is made bad (or made into a valid variant).

Families (the *kind* of a value: from the parameter's :class:`~tests.fuzz._knowledge.Spec`, else from the
baseline value's type, :func:`value_kind`) and their mutations with the expectation: ``refuse`` a bad value,
``accept`` a valid variant (compared with the baseline's answer), ``either`` a soft value (a finite answer or a
clean refusal; accepted ones are listed for review).
"""

from __future__ import annotations

import os
import random
import re

import numpy as np

#: array families: mutation -> expectation
ARRAY_MUTATIONS = {
    "coords": {"nan_entry": "refuse", "inf_entry": "refuse", "empty": "either", "cols_minus": "refuse",
               "cols_plus": "refuse", "flat": "refuse", "dim3": "refuse", "complex": "refuse", "str": "refuse",
               "object": "refuse", "bool": "either", "list": "accept", "float32": "accept", "huge_rows": "refuse"},
    "index": {"negative": "refuse", "out_of_range": "refuse", "fractional": "refuse", "nan": "refuse",
              "float_integral": "either", "empty": "either", "cols_minus": "refuse", "complex": "refuse",
              "str": "refuse", "bool": "refuse", "list": "accept", "int32": "accept", "huge_index": "refuse"},
    "vector": {"nan_entry": "refuse", "inf_entry": "refuse", "short": "refuse", "complex": "refuse",
               "str": "refuse", "dim2": "either", "empty": "refuse", "list": "accept"},
    "grid": {"nan_entry": "refuse", "complex": "refuse", "str": "refuse", "dim2": "refuse", "list": "accept",
             "huge_grid": "refuse"},
    "grid_bool": {"float": "either", "str": "refuse", "dim2": "refuse", "empty": "refuse", "huge_grid": "refuse"},
    "mask": {"short": "refuse", "str": "refuse", "list": "accept"},
    "list": {"str": "refuse", "nan_item": "refuse", "empty": "either", "object": "refuse"},
    "tuple": {"str": "refuse", "nan_item": "refuse", "empty": "either"},
    "callable_value": {"nan_out": "refuse", "complex_out": "refuse", "short_out": "refuse", "str_out": "refuse",
                       "not_callable": "refuse"},
    "object": {"str": "refuse", "none": "refuse"},
}

PATH_MUTATIONS = {
    "path_in": {"missing": "refuse", "directory": "refuse", "fifo": "refuse", "dev_zero": "refuse",
                "dev_null": "refuse", "empty_file": "refuse", "garbage": "refuse", "int": "refuse",
                "pathlib": "accept"},
    "path_out": {"directory": "refuse", "bad_ext": "refuse", "int": "refuse", "pathlib": "accept",
                 "nested_new": "either"},
}

ARRAY_KINDS = {"coords", "index", "vector", "grid", "grid_bool", "mask"}


def value_kind(v) -> str:
    """Mutation family of a baseline value."""
    if callable(v) and not isinstance(v, np.ndarray) and not isinstance(v, type):
        return "callable_value"
    if isinstance(v, (bool, np.bool_)):
        return "bool"
    if isinstance(v, (int, np.integer)):
        return "int"
    if isinstance(v, (float, np.floating)):
        return "float"
    if isinstance(v, str):
        return "str"
    if isinstance(v, tuple):
        return "tuple"
    if isinstance(v, list):
        return "list"
    if isinstance(v, np.ndarray):
        if v.dtype == bool:
            return "grid_bool" if v.ndim == 3 else "mask"
        if v.dtype.kind in "iu":
            return "index"
        if v.ndim == 3:
            return "grid"
        if v.ndim == 2:
            return "coords"
        return "vector"
    return "object"


_SCALARS = {"nan": float("nan"), "inf": float("inf"), "ninf": float("-inf"), "complex": 1j, "str": "x",
            "bool": True, "list": [1.0, 2.0], "too_big": 2 ** 64, "fractional": 1.5, "bogus": "bogus", "empty": "",
            "none": None, "bytes": b"x", "yes": "yes", "no": "no", "two": 2, "tiny": 1e-308}


def mutate_scalar(v, m: str, kind: str, spec=None):
    """A mutated scalar / option value (KeyError: the mutation does not apply)."""
    if m == "negative":
        return -1 if kind == "int" else -1.0
    if m == "zero":
        return 0 if kind == "int" else 0.0
    if m == "huge":
        return 10 ** 9 if kind == "int" else 1e308
    if m == "below_range":
        x = spec.below()
        return int(x) if kind == "int" else float(x)
    if m == "above_range":
        x = spec.above()
        return int(x) if kind == "int" else float(x)
    if m == "int":
        if kind == "float":
            if v is None or not float(v).is_integer():
                raise KeyError(m)            # no int with the same value: not a variant
            return int(v)
        return 1
    if m == "float32":
        if v is None:
            raise KeyError(m)
        return np.float32(v)
    if m == "int32":
        if v is None:
            raise KeyError(m)
        return np.int32(v)
    if m == "np_bool":
        return np.bool_(v)
    if m == "upper":
        if not isinstance(v, str) or v.upper() == v:
            raise KeyError(m)
        return v.upper()
    if m == "not_callable":
        return 5
    if m == "object":
        return object()
    if m == "dict":
        return {"x": 1}
    return _SCALARS[m]


def mutate_value(v, m: str, kind: str, fx, casedir: str):
    """The mutated array / container / callable / path (KeyError: the mutation does not apply)."""
    if kind in ARRAY_KINDS:
        A = np.asarray(v)
        if m == "nan_entry":
            B = A.astype(float).copy(); B.flat[min(1, B.size - 1)] = np.nan; return B
        if m == "inf_entry":
            B = A.astype(float).copy(); B.flat[min(1, B.size - 1)] = np.inf; return B
        if m == "empty":
            return A[:0]
        if m == "cols_minus":
            return A[:, :-1]
        if m == "cols_plus":
            return np.column_stack([A, A[:, :1]])
        if m == "flat":
            return A.ravel()
        if m in ("dim3", "dim2"):
            return A[None] if A.ndim != 3 else A[0]
        if m == "complex":
            return A + 1j
        if m == "str":
            return A.astype(str)
        if m == "object":
            B = A.astype(object); B.flat[0] = None; return B
        if m == "bool":
            return A > 0
        if m == "float":
            return A.astype(float)
        if m == "list":
            return A.tolist()
        if m == "float32":
            return A.astype(np.float32)
        if m == "int32":
            return A.astype(np.int32)
        if m == "huge_rows":
            return np.broadcast_to(A[:1], (10 ** 9,) + A.shape[1:])
        if m == "huge_grid":
            return np.broadcast_to(A.reshape(-1)[:1].reshape(()), (10000, 10000, 10000))
        if m == "negative":
            B = A.copy(); B.flat[0] = -1; return B
        if m == "out_of_range":
            return A + 10 ** 6
        if m == "huge_index":
            return np.full_like(A, 2 ** 62)
        if m == "fractional":
            return A + 0.5
        if m == "nan":
            B = A.astype(float); B.flat[0] = np.nan; return B
        if m == "float_integral":
            return A.astype(float)
        if m == "short":
            return A[:-1]
        raise KeyError(m)
    if kind in ("tuple", "list"):
        if m == "str":
            return "x"
        if m == "empty":
            return type(v)()
        if m == "object":
            return [object()]
        if m == "nan_item":
            items = list(v)
            if not items:
                raise KeyError(m)
            items[0] = np.full_like(np.asarray(items[0], float), np.nan)
            return type(v)(items)
        raise KeyError(m)
    if kind == "callable_value":
        return {"nan_out": lambda q: np.full(len(q), np.nan), "complex_out": lambda q: fx.sdf(q) + 1j,
                "short_out": lambda q: fx.sdf(q)[:-1], "str_out": lambda q: np.full(len(q), "a"),
                "not_callable": 5}[m]
    if kind == "object":
        return {"str": "x", "none": None}[m]
    if kind == "path_in":
        ext = os.path.splitext(str(v))[1]
        if m == "missing":
            return os.path.join(casedir, "missing" + ext)
        if m == "directory":
            d = os.path.join(casedir, "dir" + ext); os.makedirs(d, exist_ok=True); return d
        if m == "fifo":
            d = os.path.join(casedir, "pipe" + ext); os.mkfifo(d); return d
        if m in ("dev_zero", "dev_null"):
            d = os.path.join(casedir, m + ext)
            os.symlink("/dev/zero" if m == "dev_zero" else "/dev/null", d)
            return d
        if m in ("empty_file", "garbage"):
            d = os.path.join(casedir, m + ext)
            with open(d, "wb") as fh:
                fh.write(b"" if m == "empty_file" else garbage_bytes(4096, 7))
            return d
        if m == "int":
            return 5
        if m == "pathlib":
            import pathlib
            return pathlib.Path(v)
        raise KeyError(m)
    if kind == "path_out":
        ext = os.path.splitext(str(v))[1]
        if m == "directory":
            d = os.path.join(casedir, "odir" + ext); os.makedirs(d, exist_ok=True); return d
        if m == "bad_ext":
            return os.path.join(casedir, "out.badext")
        if m == "int":
            return 5
        if m == "pathlib":
            import pathlib
            return pathlib.Path(casedir) / os.path.basename(str(v))
        if m == "nested_new":
            return os.path.join(casedir, "a", "b", os.path.basename(str(v)))
        raise KeyError(m)
    raise KeyError(m)


def garbage_bytes(n: int, seed: int) -> bytes:
    rng = random.Random(seed)
    return bytes(rng.randrange(256) for _ in range(n))


# ------------------------------------------------------------------------------------------------ files
#: malformed / variant files: mutation -> expectation
FILE_MUTATIONS = {"truncate_half": "either", "truncate_tail": "either", "nul_byte": "refuse",
                  "huge_count": "refuse", "negative_count": "refuse", "nan_token": "refuse", "inf_token": "refuse",
                  "garbage_token": "refuse", "flip_bytes": "either", "inserted_byte": "either", "empty": "refuse",
                  "garbage": "refuse", "crlf": "accept", "bom": "either", "trailing_blank": "accept",
                  "valid": "accept"}
#: tampered saved state (.npz / .npy written by gsdf): mutation -> expectation
NPZ_MUTATIONS = {"npz_drop_key": "refuse", "npz_nan": "refuse", "npz_complex": "refuse", "npz_str": "refuse",
                 "npz_ravel": "refuse", "npz_extra_key": "either", "npz_object": "refuse", "npz_empty": "refuse"}


def _num_tokens(data: bytes):
    toks = list(re.finditer(rb"(?<=[ \n\t])-?\d+\.\d+(e[-+]?\d+)?(?=[ \r\n\t])", data))
    return toks or list(re.finditer(rb"(?<=[ \t])\d+(?=[ \r\n\t])", data))


def malform(data: bytes, m: str, name: str) -> bytes:
    """The file content ``data`` (of file ``name``) malformed by ``m`` (KeyError: does not apply)."""
    rng = random.Random(sum(map(ord, m)) * 7919 + len(data))
    try:
        text = data.decode("ascii")
    except UnicodeDecodeError:
        text = None
    if m == "truncate_half":
        return data[: len(data) // 2]
    if m == "truncate_tail":
        return data[:-7]
    if m == "nul_byte":
        return data[: len(data) // 3] + b"\x00" + data[len(data) // 3:]
    if m == "inserted_byte":
        k = len(data) * 2 // 3
        return data[:k] + b"\x01" + data[k:]
    if m == "empty":
        return b""
    if m == "garbage":
        return garbage_bytes(2048, 11)
    if m == "flip_bytes":
        b = bytearray(data)
        for _ in range(8):
            b[rng.randrange(len(b))] ^= 0xFF
        return bytes(b)
    if m == "valid":
        return data
    if text is not None:
        if m == "crlf":
            return data.replace(b"\r\n", b"\n").replace(b"\n", b"\r\n")
        if m == "bom":
            return b"\xef\xbb\xbf" + data
        if m == "trailing_blank":
            return data + b"\n\n   \n"
    if m in ("huge_count", "negative_count"):
        new = b"999999999999" if m == "huge_count" else b"-5"
        if name.endswith(".stl") and text is None and len(data) >= 84:      # binary STL: uint32 count at 80
            return data[:80] + (b"\xff\xff\xff\xff" if m == "huge_count" else b"\x00\x00\x00\x00") + data[84:]
        if name.endswith(".npy"):
            mm = re.search(rb"'shape': \((\d+)", data[:256])
            if mm:
                return data[: mm.start(1)] + new + data[mm.end(1):]
        pat = re.compile(rb"(element \w+ |NumberOfPoints=\"|POINTS |^)(\d+)(?=[ \r\n\"])", re.M)
        mm = pat.search(data[:4096])
        if not mm:
            raise KeyError(m)
        return data[: mm.start(2)] + new + data[mm.end(2):]
    if m in ("nan_token", "inf_token", "garbage_token") and text is not None:
        toks = _num_tokens(data)
        if not toks:
            raise KeyError(m)
        mt = toks[len(toks) // 2]
        new = {"nan_token": b"nan", "inf_token": b"inf", "garbage_token": b"x7"}[m]
        return data[: mt.start()] + new + data[mt.end():]
    raise KeyError(m)


def tamper_npz(src: str, dst: str, m: str) -> None:
    """Write ``dst``: the ``.npz`` ``src`` with one array tampered (KeyError: does not apply)."""
    with np.load(src, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    num = [k for k, a in arrays.items() if a.dtype.kind == "f" and a.size > 1]
    big = max(arrays, key=lambda k: arrays[k].size)
    if m == "npz_drop_key":
        del arrays[big]
    elif m == "npz_nan":
        if not num:
            raise KeyError(m)
        a = arrays[num[0]].copy(); a.flat[a.size // 2] = np.nan; arrays[num[0]] = a
    elif m == "npz_complex":
        arrays[big] = arrays[big] + 1j
    elif m == "npz_str":
        arrays[big] = arrays[big].astype(str)
    elif m == "npz_ravel":
        if arrays[big].ndim < 2:
            arrays[big] = arrays[big][:-1]
        else:
            arrays[big] = arrays[big].ravel()
    elif m == "npz_extra_key":
        arrays["zz_extra"] = np.arange(3)
    elif m == "npz_object":
        a = np.empty(2, object); a[0] = None
        arrays[big] = a
    elif m == "npz_empty":
        arrays[big] = arrays[big][:0]
    else:
        raise KeyError(m)
    with open(dst, "wb") as fh:
        np.savez(fh, **arrays)
