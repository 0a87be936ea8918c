"""Electric fields of EODs, intrinsic and induced dipoles, and their wall images."""

from .fields import coulomb_constant, dipole_field, monopole_field
from .images import image_indices, image_sources
from .plan import Effect, EffectPlan, build_plan
from .snapshot import Snapshot, SnapshotBatch

__all__ = ["Effect", "EffectPlan", "Snapshot", "SnapshotBatch", "build_plan", "coulomb_constant",
           "dipole_field", "image_indices", "image_sources", "monopole_field"]
