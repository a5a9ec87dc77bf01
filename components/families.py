"""Element family names of the planet-bearing and gear-train scenes: one family per contact kind (and the
ground supports of sun, ring and carrier), so builders, the outputs module, the runner and the numerics
scripts all name them from here."""
from types import MappingProxyType

__all__ = ["FAMILY", "MESH_FAMILY"]

FAMILY = MappingProxyType({"race_inner": "race_inner", "race_outer": "race_outer", "pocket": "pocket",
                           "retention": "pocket_retention", "guide": "guide", "drag": "drag", "linear": "bearing_linear", "support": "support",
                           "gyroscopic": "planet_gyroscopic", "pocket_film": "pocket_film",
                           "race_film_inner": "race_film_inner", "race_film_outer": "race_film_outer",
                           "cage_drag": "cage_drag", "pin_beam": "pin_beam",
                           "pin_gyroscopic": "pin_gyroscopic"})
MESH_FAMILY = MappingProxyType({"sun_inner": "mesh_sa", "inner_outer": "mesh_ab", "outer_ring": "mesh_br"})
