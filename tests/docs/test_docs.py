"""The documentation cannot drift from the code: the site builds with warnings as errors (offline), every public
name has a numpy-style docstring with an Examples section and a reference entry, every guide page's code blocks
and every script in examples/ run (each failure names its page / block or script)."""

from __future__ import annotations

import glob
import importlib.util
import inspect
import os
import re
import subprocess
import sys
import warnings

import pytest

import gsdf

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DOCS = os.path.join(ROOT, "docs")
PAGES = sorted(glob.glob(os.path.join(DOCS, "guide", "*.md"))) + [os.path.join(DOCS, "formats.md")]
EXAMPLES = sorted(glob.glob(os.path.join(ROOT, "examples", "*.py")))
TIMEOUT = 600  # per page / script / build: a hang fails instead of stalling CI


def _env():
    env = dict(os.environ)
    env["PYTHONPATH"] = os.path.join(ROOT, "src") + os.pathsep + env.get("PYTHONPATH", "")
    env["MPLBACKEND"] = "Agg"
    return env


def _section(doc: str, name: str) -> str:
    """Body of a numpy-style section ``name`` of a docstring ('' when absent)."""
    m = re.search(rf"^{name}\n-{{{len(name)}}}\n(.*?)(?=^\S[^\n]*\n-{{3,}}\n|\Z)", doc, re.M | re.S)
    return m.group(1).strip() if m else ""


@pytest.mark.parametrize("name", gsdf.__all__)
def test_public_name_has_docstring_with_examples(name):
    doc = inspect.getdoc(getattr(gsdf, name)) or ""
    assert len(doc.split("\n", 1)[0]) > 10, f"gsdf.{name}: missing or empty docstring summary line"
    examples = _section(doc, "Examples")
    assert examples, f"gsdf.{name}: the docstring has no numpy-style 'Examples' section"
    assert ">>>" in examples, f"gsdf.{name}: the Examples section has no '>>>' example"


def _public_callables():
    """``(name, function, bound)`` of every public name of gsdf that is a function or a class (its constructor's
    parameters are the class's) and of every public method of the public classes (``bound``: the first
    parameter is self / cls, not documented)."""
    out = []
    for name in gsdf.__all__:
        obj = getattr(gsdf, name)
        if inspect.isclass(obj):
            out.append((name, obj, False))
            for m in sorted(dir(obj)):
                if m.startswith("_"):
                    continue
                raw = inspect.getattr_static(obj, m)
                fn = raw.__func__ if isinstance(raw, (staticmethod, classmethod)) else raw
                if inspect.isfunction(fn):
                    out.append((f"{name}.{m}", fn, not isinstance(raw, staticmethod)))
        elif callable(obj):
            out.append((name, obj, False))
    return out


PUBLIC = _public_callables()


@pytest.mark.skipif(importlib.util.find_spec("numpydoc") is None,
                    reason='numpydoc is not installed (pip install -e ".[docs]")')
@pytest.mark.parametrize("name,obj,bound", PUBLIC, ids=[p[0] for p in PUBLIC])
def test_public_callable_documents_every_parameter(name, obj, bound):
    """Each parameter of a public function, class or public method has an entry in its numpy-style Parameters
    section (a class: Parameters, Other Parameters or Attributes), and each public method has an Examples
    section; parsed with numpydoc's docscrape, as the reference pages render them."""
    from numpydoc.docscrape import NumpyDocString

    doc = inspect.getdoc(obj) or ""
    assert doc.strip(), f"gsdf.{name}: no docstring"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")                      # numpydoc warns about sections it does not know
        parsed = NumpyDocString(doc)
    sections = ("Parameters", "Other Parameters") + (("Attributes",) if inspect.isclass(obj) else ())
    documented = {n.strip().lstrip("*") for sec in sections for item in parsed[sec] for n in item.name.split(",")}
    params = list(inspect.signature(obj).parameters.values())
    if bound and params:
        params = params[1:]
    for sec in sections:                 # a paragraph inside a section is parsed as a parameter: shown as code
        for item in parsed[sec]:
            assert re.fullmatch(r"\*{0,2}\w+(, ?\*{0,2}\w+)*", item.name.strip()), \
                f"gsdf.{name}: {item.name[:60]!r} under {sec} is not a parameter name (a paragraph? move it to Notes)"
    missing = [p.name for p in params if p.name not in documented]
    assert not missing, (f"gsdf.{name}: the docstring's Parameters section does not document {missing}"
                         + ("" if parsed["Parameters"] else " (it has no Parameters section)"))
    if "." in name:
        assert parsed["Examples"], f"gsdf.{name}: the docstring has no Examples section"


def test_every_public_name_in_the_api_reference():
    text = open(os.path.join(DOCS, "api", "index.rst"), encoding="utf-8").read()
    listed = set(re.findall(r"^   (\w+)$", text, re.M))
    assert not set(gsdf.__all__) - listed, f"names missing from docs/api/index.rst: {set(gsdf.__all__) - listed}"
    assert not listed - set(gsdf.__all__), f"docs/api/index.rst lists non-public names: {listed - set(gsdf.__all__)}"


def test_guide_pages_in_the_toctree():
    index = open(os.path.join(DOCS, "index.md"), encoding="utf-8").read()
    for page in PAGES:
        rel = os.path.relpath(page, DOCS)[:-3]
        assert rel in index, f"docs/index.md does not list {rel}"


def test_conf_is_offline():
    conf = open(os.path.join(DOCS, "conf.py"), encoding="utf-8").read()
    assert "sphinx.ext.intersphinx" not in conf
    for page in glob.glob(os.path.join(DOCS, "**", "*.md"), recursive=True):
        for target in re.findall(r"!\[[^\]]*\]\(([^)]+)\)", open(page, encoding="utf-8").read()):
            assert not re.match(r"\w+://", target), f"{page}: remote image {target}"


@pytest.mark.skipif(not all(importlib.util.find_spec(m) for m in ("sphinx", "numpydoc", "myst_parser")),
                    reason='the docs extra is not installed (pip install -e ".[docs]")')
def test_docs_build_without_warnings(tmp_path):
    r = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-E", "-b", "html", "-d",
                        str(tmp_path / "doctrees"), DOCS, str(tmp_path / "html")],
                       capture_output=True, text=True, timeout=TIMEOUT, env=_env(), cwd=ROOT)
    assert r.returncode == 0, f"sphinx -W failed:\n{r.stderr[-6000:]}"
    html = (tmp_path / "html" / "index.html").read_text(encoding="utf-8")
    assert "guide/inside_outside.html" in html
    generated = tmp_path / "html" / "api" / "generated"
    for name in gsdf.__all__:
        assert (generated / f"gsdf.{name}.html").exists(), f"no page for gsdf.{name}"
    # a page per public method, with its parameters
    page = (generated / "gsdf.SurfaceSignedHeatSolver.compute_distance.html").read_text(encoding="utf-8")
    assert "Parameters" in page and "level_set_constraint" in page and "Returns" in page and "Examples" in page
    # no page shows markup that was not rendered (RST roles or literals left as text)
    import html as html_lib

    for f in (tmp_path / "html").rglob("*.html"):
        text = html_lib.unescape(re.sub(r"<[^>]+>", "", f.read_text(encoding="utf-8")))
        raw = re.findall(r":(?:func|class|meth|mod|attr|data|ref|doc):`|``[^`\n]+``|^\.\. [\w-]+::", text, re.M)
        assert not raw, f"{f.relative_to(tmp_path / 'html')} shows raw markup: {raw[:3]}"


@pytest.mark.parametrize("page", PAGES, ids=[os.path.basename(p) for p in PAGES])
def test_guide_page_code_runs(page, tmp_path):
    r = subprocess.run([sys.executable, os.path.join(DOCS, "run_blocks.py"), page, "--cwd", str(tmp_path)],
                       capture_output=True, text=True, timeout=TIMEOUT, env=_env())
    assert r.returncode == 0, f"{os.path.relpath(page, ROOT)}:\n{r.stderr[-6000:]}"


def _gallery():
    spec = importlib.util.spec_from_file_location("make_gallery", os.path.join(DOCS, "make_gallery.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)              # defines the pictures; runs nothing
    return mod.PICTURES


GUIDE = sorted(glob.glob(os.path.join(DOCS, "guide", "*.md")))


@pytest.mark.parametrize("page", GUIDE + [os.path.join(ROOT, "README.md")],
                         ids=[os.path.basename(p) for p in GUIDE] + ["README.md"])
def test_page_opens_with_a_gallery_picture(page):
    """Every guide page and the README open with a picture of the task on real data, made by
    docs/make_gallery.py (its committed output): at least 800 px wide, under 300 KB."""
    from PIL import Image

    text = open(page, encoding="utf-8").read()
    body = [line for line in text.splitlines()[1:] if line.strip()]
    m = re.fullmatch(r"!\[[^\]]+\]\((\S*img/(\w+)\.png)\)", body[0].strip())
    assert m, f"{os.path.basename(page)}: does not open with a picture (first line: {body[0][:80]!r})"
    target, name = m.groups()
    assert name in _gallery(), f"{os.path.basename(page)} opens with {target}, which make_gallery.py does not make"
    png = os.path.normpath(os.path.join(os.path.dirname(page), target))
    assert os.path.isfile(png), f"{target} is not committed (python docs/make_gallery.py --only {name})"
    with Image.open(png) as im:
        assert im.size[0] >= 800, f"{target}: {im.size[0]} px wide"
    assert os.path.getsize(png) < 300_000, f"{target}: {os.path.getsize(png)} bytes"


def test_every_guide_picture_is_a_gallery_picture():
    made = {f"{n}.png" for n in _gallery()}
    committed = set(os.listdir(os.path.join(DOCS, "guide", "img")))
    assert committed == made, f"not made by docs/make_gallery.py: {sorted(committed - made)}; missing: " \
                              f"{sorted(made - committed)}"


@pytest.mark.parametrize("script", EXAMPLES, ids=[os.path.basename(p) for p in EXAMPLES])
def test_example_runs_and_writes_a_png(script, tmp_path):
    r = subprocess.run([sys.executable, script], capture_output=True, text=True, timeout=TIMEOUT, env=_env(),
                       cwd=tmp_path)
    assert r.returncode == 0, f"examples/{os.path.basename(script)} failed:\n{r.stderr[-6000:]}"
    pngs = list(tmp_path.glob("*.png"))
    assert pngs, f"examples/{os.path.basename(script)} wrote no PNG"
    for p in pngs:
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", p


def test_run_blocks_names_the_failing_block(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("# t\n\n```python\nx = 1\n```\n\ntext\n\n```python\nassert x == 2, 'boom'\n```\n")
    r = subprocess.run([sys.executable, os.path.join(DOCS, "run_blocks.py"), str(page), "--cwd", str(tmp_path)],
                       capture_output=True, text=True, timeout=60, env=_env())
    assert r.returncode == 1
    assert "block 2 (line 9" in r.stderr and "boom" in r.stderr

