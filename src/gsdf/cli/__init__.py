"""The ``gsdf`` command line (one module per subcommand)."""
