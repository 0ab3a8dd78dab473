"""gsdf's generated fuzz suite (tests/fuzz): the cases are derived from the package, not written by hand.

* ``python -m tests.fuzz`` — every generated case (hours on 2 cores); ``--sample N --seed S`` a stratified
  sample; ``--areas api,cli,files`` (or ``api:scale``, ``cli:env`` ...); ``--jobs J``; ``--json out.json``;
  ``--list`` the case ids; ``--gaps`` the parameters without a known valid value; ``--only TEXT``; ``--ids FILE``
  exactly the listed cases. A case that hangs is run once more (a cold numba cache); ``GSDF_WORK_LIMIT`` is half
  the case timeout unless set.
* ``tests/fuzz/test_fuzz_sample.py`` — the fixed sample run by pytest in CI, with the explicit list of cases
  that still fail because of a known open defect (``KNOWN_OPEN``).

Modules: :mod:`._cases` (generation), :mod:`._knowledge` (what is valid for each parameter),
:mod:`._fixtures` (valid values by parameter name), :mod:`._mutations`, :mod:`.strategies` (hypothesis
strategies for broken geometry), :mod:`._execute` (one case + classification), :mod:`._runner`.
"""
