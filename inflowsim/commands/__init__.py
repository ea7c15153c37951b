"""One module per ``inflowsim`` command (see :mod:`inflowsim.cli`)."""
