"""What a command line needs of the scene module before it reads or generates a scene: imports
nothing heavy (no numpy, shapely or YAML), so ``--help`` and a usage error stay fast."""

from __future__ import annotations

from pathlib import Path

KINDS = ("vr", "gen1", "gen2", "unstructured")
"""The generators' scene kinds (``generators.generate_scene``)."""
MAX_GENERATED = 100
"""Most obstacles a generator places (tables fill up well before)."""
DEFAULT_SCENE_FILE = Path(__file__).resolve().parents[1] / "scenes" / "default.yaml"
"""The bundled default scene (Generalization I, seed 3), which ``run_scene`` runs without arguments."""
