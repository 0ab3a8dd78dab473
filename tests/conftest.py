"""Shared pytest configuration: hypothesis profiles for tests/test_properties.py.

``ci`` (default) is bounded so the property tests finish in a few minutes on 2 cores; ``long`` explores far
more cases: ``python -m pytest tests/test_properties.py --hypothesis-profile=long``.
"""

try:
    from hypothesis import HealthCheck, settings
except ImportError:  # hypothesis is in the "test" extra; without it only test_properties.py is skipped
    pass
else:
    _common = dict(deadline=None, print_blob=True,
                   suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                          HealthCheck.filter_too_much])
    # ci: derandomized, so CI runs the same examples every time (a failure reproduces); long: fresh random ones
    settings.register_profile("ci", max_examples=12, derandomize=True, **_common)
    settings.register_profile("long", max_examples=600, derandomize=False, **_common)
    settings.load_profile("ci")
