"""Fixtures of the conformance suite (tests/conformance): the vendored peer assets, unpacked once per session."""

from __future__ import annotations

import gzip

import pytest

from tests.conformance.helpers import DATA


@pytest.fixture(scope="session")
def unpacked(tmp_path_factory):
    """``unpacked(peer, name)``: path of a vendored asset; ``name.gz`` is decompressed once per session into a
    file with the original name (the test reads the peer's exact bytes)."""
    root = tmp_path_factory.mktemp("assets")
    cache = {}

    def get(peer: str, name: str) -> str:
        key = (peer, name)
        if key in cache:
            return cache[key]
        p = DATA / peer / name
        if p.exists():
            cache[key] = str(p)
            return cache[key]
        gz = DATA / peer / (name + ".gz")
        if not gz.exists():
            pytest.fail(f"missing vendored asset data/{peer}/{name}(.gz)")
        out = root / peer / name
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_bytes(gzip.decompress(gz.read_bytes()))
        cache[key] = str(out)
        return cache[key]

    return get


def pytest_collection_modifyitems(config, items):
    """Tests marked ``slow`` (a peer's full-size input) run only with GSDF_SLOW_TESTS=1."""
    import os

    if os.environ.get("GSDF_SLOW_TESTS") == "1":
        return
    skip = pytest.mark.skip(reason="slow: the peer's full-size input (set GSDF_SLOW_TESTS=1)")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)
