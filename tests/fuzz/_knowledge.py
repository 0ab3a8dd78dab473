"""What is valid for each parameter, derived from the package itself — nothing per function is written here.

A parameter's :class:`Spec` comes from, in order of trust:

1. its numpydoc entry (``Parameters`` / ``Attributes`` of the callable's or class's docstring): the type line
   (``int >= 2``, ``float in [0, 1]``, ``{"jet", "learned"}``, ``positive``, ``optional``, ``bool`` ...);
2. its annotation (``float | None``, ``bool``, ``XOptions | None``, ``Callable``);
3. its default value's type;
4. its name: counts (``k``, ``resolution``, ``n_samples`` ...: zero and negatives are invalid, 10⁹ must be refused
   by the memory/work guard), positive quantities (``t``, ``eps``, ``time_limit``, ``spacing`` ...), non-negative
   ones (``margin``, ``pad``, ``max_retries`` ...).

The spec decides each mutation's expectation: ``refuse`` (a bad value: must raise ``ValueError``), ``accept`` (a
valid variant: must answer like the baseline) or ``either`` (soft: a clean refusal or a finite answer; an
acceptance is listed for review).
"""

from __future__ import annotations

import dataclasses
import inspect
import re
from dataclasses import dataclass, field

#: counts whose zero (and negatives) are invalid
COUNT_POSITIVE = {"k", "k_eval", "k_fallback", "fit_k", "n_samples", "n_points", "resolution", "heat_resolution",
                  "leaf_size", "chunk", "width", "height", "candidates", "max_edges", "n", "workers", "layers"}
#: counts where zero is meaningful (no steps, no retries ...): negatives invalid
COUNT_NONNEG = {"steps", "bisection_steps", "bisection", "max_retries", "iterations", "subdivide", "max_iterations",
                "seed", "order", "max_memory", "threads", "isolines"}
#: sizes: 10⁹ must be refused (memory / work guard) instead of running out of memory or time
SIZE = {"resolution", "heat_resolution", "n_samples", "n_points", "width", "height", "k", "k_eval", "k_fallback",
        "fit_k", "candidates", "iterations", "max_iterations", "steps", "bisection_steps", "bisection", "n",
        "max_edges", "layers", "size"}
#: quantities that must be > 0
POSITIVE = {"t", "t_coef", "eps", "epsilon", "time_limit", "spacing", "C", "lam", "r_eval", "unit_mm",
            "normal_radius", "theta", "beta", "scheduler_timeout", "sigma", "radius"}
#: quantities that must be >= 0
NONNEG = {"margin", "pad", "ridge", "kd_eps", "slack", "band", "cluster_gap", "outlier_gap", "curvature_cap",
          "uniform_fraction", "normal_weight", "fill", "soft_weight"}


@dataclass
class Spec:
    """What a parameter takes. ``kind`` picks the mutation family; the bounds decide which values are bad."""

    name: str
    kind: str                        # float int str bool none callable options path_in path_out tuple required
    optional: bool = False           # None is a valid value
    choices: tuple = ()
    lo: float | None = None
    lo_open: bool = False
    hi: float | None = None
    hi_open: bool = False
    size: bool = False               # a size: 10**9 must be refused
    doc: str = ""
    sources: list = field(default_factory=list)   # where the knowledge came from (doc / annotation / name)
    options_class: str = ""          # kind == "options": the dataclass name

    def below(self):
        """A value below the valid range (None: no lower bound known)."""
        if self.lo is None:
            return None
        return self.lo if self.lo_open else self.lo - (1 if self.kind == "int" else 0.5)

    def above(self):
        if self.hi is None:
            return None
        return self.hi if self.hi_open else self.hi + (1 if self.kind == "int" else 0.5)

    def valid(self, x: float) -> bool:
        if self.lo is not None and (x < self.lo or (self.lo_open and x == self.lo)):
            return False
        if self.hi is not None and (x > self.hi or (self.hi_open and x == self.hi)):
            return False
        return True


# ------------------------------------------------------------------------------------------------ numpydoc
_SECTION = re.compile(r"^\s*(Parameters|Attributes|Other Parameters)\s*\n\s*-{3,}\s*\n", re.M)
_END = re.compile(r"^\s*[A-Z][A-Za-z ]+\n\s*-{3,}\s*$", re.M)


def doc_types(obj) -> dict:
    """``{name: type line}`` of the numpydoc Parameters / Attributes sections of ``obj``'s docstring."""
    doc = inspect.getdoc(obj) or ""
    out = {}
    for m in _SECTION.finditer(doc):
        body = doc[m.end():]
        e = _END.search(body)
        body = body[: e.start()] if e else body
        for line in body.splitlines():
            if not line or line[0].isspace():
                continue
            mm = re.match(r"^([\w*, ]+?)\s*:\s*(.*)$", line)
            if not mm:
                continue
            for n in mm.group(1).split(","):
                n = n.strip().lstrip("*")
                if n:
                    out.setdefault(n, mm.group(2).strip())
    return out


_NUM = r"[-+]?(?:\d+\.?\d*(?:e[-+]?\d+)?|inf)"


def parse_type_line(text: str, spec: Spec) -> None:
    """Fill ``spec`` from a numpydoc type line (in place)."""
    t = text.strip()
    if not t:
        return
    low = t.lower()
    m = re.search(r"\{([^}]*)\}", t)
    if m:
        items = [x.strip().strip("\"'") for x in m.group(1).split(",") if x.strip()]
        if items:
            spec.choices = tuple(items)
            spec.sources.append("doc choices")
    m = re.search(rf"in\s*([\[(])\s*({_NUM})\s*,\s*({_NUM})\s*([\])])", low)
    if m:
        spec.lo, spec.hi = float(m.group(2)), float(m.group(3))
        spec.lo_open, spec.hi_open = m.group(1) == "(", m.group(4) == ")"
        spec.sources.append("doc range")
    m = re.search(rf"(>=|>|≥)\s*({_NUM})", low)
    if m:
        spec.lo, spec.lo_open = float(m.group(2)), m.group(1) == ">"
        spec.sources.append("doc bound")
    m = re.search(rf"(<=|<|≤)\s*({_NUM})", low)
    if m:
        spec.hi, spec.hi_open = float(m.group(2)), m.group(1) == "<"
    if re.search(r"\bnon-?negative\b", low):
        spec.lo, spec.lo_open = 0.0, False
        spec.sources.append("doc non-negative")
    elif re.search(r"\bpositive\b", low):
        spec.lo, spec.lo_open = 0.0, True
        spec.sources.append("doc positive")
    m = re.search(r"\bin\s+(-?\d+)\s*\.\.\s*(-?\d+)", low)
    if m:
        spec.lo, spec.hi, spec.lo_open, spec.hi_open = float(m.group(1)), float(m.group(2)), False, False
        spec.sources.append("doc range")
    outside = re.sub(r"\{[^}]*\}", "", t)
    if re.search(r"\boptional\b", outside.lower()) or re.search(r"\bNone\b", outside):
        spec.optional = True


def _kind_of_annotation(ann: str) -> tuple[str, bool, str]:
    """(kind, optional, options class) from an annotation string ('' when it says nothing useful)."""
    if not isinstance(ann, str):
        ann = getattr(ann, "__name__", str(ann))
    a = ann.replace(" ", "")
    parts = [x for x in a.split("|") if x]
    optional = "None" in parts or a.startswith("Optional[")
    parts = [x for x in parts if x != "None"]
    if len(parts) == 1:
        p = parts[0].strip("'\"")
        if p.endswith("Options"):
            return "options", optional, p
        if p.startswith("Callable"):
            return "callable", optional, ""
        if p in ("float", "int", "str", "bool", "tuple"):
            return p, optional, ""
    if parts and all(x in ("float", "int") for x in parts):
        return "float", optional, ""
    if parts and set(parts) <= {"float", "str"}:
        return "float", optional, ""        # soft_weight: float | str | None
    return "", optional, ""


def spec_of(p: inspect.Parameter, doc: str, target: str) -> Spec:
    """The :class:`Spec` of one parameter of ``target``."""
    from tests.fuzz._fixtures import PATH_NAMES, WRITER

    s = Spec(p.name, "", doc=doc)
    d = p.default
    if p.name in PATH_NAMES:
        s.kind = "path_out" if (WRITER.search(target) or p.name in ("out", "screenshot")) else "path_in"
        s.sources.append("name")
        return s
    kind, opt, ocls = _kind_of_annotation(p.annotation) if p.annotation is not p.empty else ("", False, "")
    if kind:
        s.kind, s.optional, s.options_class = kind, opt, ocls
        s.sources.append("annotation")
    if not s.kind and d is not p.empty:
        s.kind = ("bool" if isinstance(d, bool) else "int" if isinstance(d, int) else
                  "float" if isinstance(d, float) else "str" if isinstance(d, str) else
                  "tuple" if isinstance(d, tuple) else "none" if d is None else "object")
        s.sources.append("default")
    if not s.kind:
        s.kind = "required"
    if d is None:
        s.optional = True
    parse_type_line(doc, s)
    low = doc.lower()
    if s.kind in ("none", "required", "object", "tuple") and doc:
        # the doc's type line may name a scalar type the signature does not
        if re.match(r"^(float|int)\b", low) and "array" not in low and "(" not in low.split(",")[0]:
            s.kind = "int" if low.startswith("int") else "float"
            s.sources.append("doc type")
        elif re.match(r"^bool\b", low):
            s.kind = "bool"
            s.sources.append("doc type")
        elif re.match(r"^callable\b", low):
            s.kind = "callable"
            s.sources.append("doc type")
        elif s.choices and s.kind != "required" and all(not c.lstrip("-").isdigit() for c in s.choices):
            s.kind = "str"
    if s.kind == "int" and s.choices and all(c.lstrip("-").isdigit() for c in s.choices):
        vals = [int(c) for c in s.choices]
        s.lo, s.hi = min(vals), max(vals)
        s.sources.append("doc int choices")
    # names: what counts and quantities are
    n = p.name
    if s.kind in ("int", "float", "none") and "doc bound" not in s.sources and "doc range" not in s.sources \
            and "doc positive" not in s.sources and "doc non-negative" not in s.sources and s.lo is None:
        if n in COUNT_POSITIVE:
            s.lo, s.lo_open = (1.0, False) if s.kind != "float" else (0.0, True)
            s.sources.append("name: count")
        elif n in COUNT_NONNEG:
            s.lo, s.lo_open = 0.0, False
            s.sources.append("name: count >= 0")
        elif n in POSITIVE:
            s.lo, s.lo_open = 0.0, True
            s.sources.append("name: positive")
        elif n in NONNEG:
            s.lo, s.lo_open = 0.0, False
            s.sources.append("name: non-negative")
    if n == "progress" and s.kind in ("none", "callable"):
        s.kind, s.optional = "callable", True
        s.sources.append("name: progress callback")
    if n in SIZE:
        s.size = True
    if s.kind == "none" and n in COUNT_POSITIVE | COUNT_NONNEG:
        s.kind = "int"
    if s.kind == "none" and n in POSITIVE | NONNEG:
        s.kind = "float"
    return s


def specs(target: str, sig: inspect.Signature, obj) -> dict:
    """``{name: Spec}`` for every parameter of ``target`` (``obj``: the callable whose docstring documents it)."""
    docs = doc_types(obj)
    return {p.name: spec_of(p, docs.get(p.name, ""), target) for p in sig.parameters.values()
            if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD) and not p.name.startswith("_")}


def option_classes(ns) -> dict:
    """``{class name: [Spec of each field]}`` for the public options dataclasses of namespace ``ns``."""
    out = {}
    for name in sorted(getattr(ns, "__all__", [])):
        cls = getattr(ns, name)
        if inspect.isclass(cls) and dataclasses.is_dataclass(cls) and name.endswith("Options"):
            sig = inspect.signature(cls)
            out[name] = specs(name, sig, cls)
    return out


# ------------------------------------------------------------------------------------------------ expectations
def scalar_mutations(s: Spec) -> dict:
    """``{mutation: expectation}`` for a scalar parameter from its spec."""
    if s.kind == "float":
        m = {"nan": "refuse", "inf": "refuse", "ninf": "refuse", "complex": "refuse", "str": "refuse",
             "bool": "refuse", "list": "refuse", "int": "accept", "float32": "accept",
             "negative": "either", "zero": "either", "huge": "either", "tiny": "either"}
        for mut, x in (("negative", -1.0), ("zero", 0.0), ("huge", 1e308), ("tiny", 1e-308)):
            if s.lo is not None or s.hi is not None:
                m[mut] = "either" if s.valid(x) else "refuse"
        if s.below() is not None and s.below() not in (-1.0, 0.0):
            m["below_range"] = "refuse"
        if s.above() is not None:
            m["above_range"] = "refuse"
        if s.optional:
            m["none"] = "accept"
        return m
    if s.kind == "int":
        m = {"too_big": "refuse", "fractional": "refuse", "nan": "refuse", "str": "refuse", "bool": "refuse",
             "complex": "refuse", "int32": "accept", "negative": "either", "zero": "either",
             "huge": "refuse" if s.size else "either"}
        for mut, x in (("negative", -1), ("zero", 0)):
            if s.lo is not None or s.hi is not None:
                m[mut] = "either" if s.valid(x) else "refuse"
        if s.hi is not None and not s.valid(10 ** 9):
            m["huge"] = "refuse"
        if s.below() is not None and s.below() not in (-1, 0):
            m["below_range"] = "refuse"
        if s.above() is not None:
            m["above_range"] = "refuse"
        if s.optional:
            m["none"] = "accept"
        return m
    if s.kind == "str":
        if s.choices:
            return {"bogus": "refuse", "empty": "refuse", "bytes": "refuse", "int": "refuse", "upper": "either",
                    "none": "accept" if s.optional else "refuse"}
        # free text (a name, a title): only wrong types are bad
        return {"empty": "either", "bytes": "refuse", "int": "either", "none": "accept" if s.optional else "refuse"}
    if s.kind == "bool":
        return {"yes": "refuse", "no": "refuse", "two": "refuse", "none": "either", "np_bool": "accept",
                "str": "refuse"}
    if s.kind == "callable":
        m = {"not_callable": "refuse", "object": "refuse"}
        if s.optional:
            m["none"] = "accept"
        return m
    if s.kind == "options":
        return {"dict": "refuse", "str": "refuse", "other_options": "refuse", "none": "accept"}
    if s.kind == "none":
        return {"nan": "refuse", "complex": "refuse", "object": "refuse", "str": "either"}
    if s.kind == "tuple":
        return {"str": "refuse", "nan_item": "refuse", "empty": "either"}
    return {}
