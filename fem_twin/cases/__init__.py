"""Case files shipped with the package (``fem-twin example DIR`` writes them out)."""
