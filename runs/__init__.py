"""The scene files shipped with beltsim: ``beltsim run NAME`` runs ``NAME.toml``.

The build installs this folder as the package ``beltsim.scenes`` (package data, see
pyproject.toml); this file makes it a regular package, which an editable install maps
here as it maps a wheel's copy. Runs write their outputs to ``runs/out/``.
"""
