"""Physics layer: blade-element flapping and loads (Eqs. 1-4), momentum theory and
Pitt-Peters values, multiblade coordinates.  Pure functions of named quantities."""


__all__: list = []
