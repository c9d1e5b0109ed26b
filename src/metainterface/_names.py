"""Names the command line offers as choices, free of heavy imports.

``metainterface --help`` and an argument error must answer without importing torch, so the
choices of ``--physics``, ``--method`` and ``--format`` are spelt here; the library's
registries (``physics.registry.MODELS``, ``inverse.pipeline.METHODS``, ``io.export.FORMATS``)
are built on them, and tests/test_cli_startup.py checks that the two agree.
"""

from __future__ import annotations

#: The built-in forward models (``physics.registry.MODELS``), and the one used where none is named.
MODEL_NAMES: tuple[str, ...] = ("independent", "interacting")
DEFAULT_MODEL = "independent"
#: The design methods (``inverse.pipeline.METHODS``).
METHOD_NAMES: tuple[str, ...] = ("surrogate", "multistart", "hertz")
#: The export formats (``io.export.FORMATS``).
EXPORT_FORMATS: tuple[str, ...] = ("stl", "png", "tiff", "npy")
#: The BEM contact solvers (``validation.engines.ENGINES``), and the default one.
ENGINE_NAMES: tuple[str, ...] = ("torch", "tamaas")
DEFAULT_ENGINE = "torch"
#: When a friction law's rows are replaced by a monotone fit (``units.friction.FIT_CHOICES``).
FIT_NAMES: tuple[str, ...] = ("auto", "always", "never")
