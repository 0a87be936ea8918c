"""Electric fields of EODs, intrinsic and induced dipoles, their wall images, and the raw receptor readings.

The ground floor of the simulator: it knows bodies, fields and sensors, never a
task. Modules, from the formulas up:

- ``fields``: closed-form monopole and dipole fields (SI units, softened); polarisability, induced dipoles.
- ``images``: first- and higher-order wall images of sources (insulating walls).
- ``geometry``: where the receptors sit on the body (angles, positions, normals).
- ``snapshot``: :class:`Snapshot` (one arena, validated) and :class:`SnapshotBatch` (B arenas, the kernels' input).
- ``plan``: the effect plan: which effects a :class:`Scene` calls for, and every constant the kernels need.
- ``readings``: :class:`RawReadings`, the result of both paths below.
- ``reference``: the brute-force oracle (numpy, every source at every sensor); tests and accuracy studies only.
- ``fast``: the fast path's Python side: plan -> kernel inputs, batch -> raw readings.
- ``kernel_inputs``: the named tuples the kernels take (plan tables, batch arrays, outputs, scratch arrays).
- ``kernels``: numba field kernels shared by the fast path (monopoles, sensor placement, induction, far points).
- ``far_field``: the far-field tables: trigonometric interpolation from a few points on the sensor circle.
- ``sources``: source lists of an arena, culling bounds, sharing far sources between agents, bucketing.
- ``sense_kernel``: the per-batch and per-agent assembly of raw readings (numba).
- ``trig``: a vectorised sincos for the kernels.
"""

from .fields import coulomb_constant, dipole_field, monopole_field
from .geometry import ampullary_angles, knollenorgan_angles, mormyromast_angles, sensor_frame
from .images import image_indices, image_sources
from .plan import Effect, EffectPlan, Scene, build_plan
from .readings import RawReadings, empty_readings
from .snapshot import Snapshot, SnapshotBatch

__all__ = ["Effect", "EffectPlan", "RawReadings", "Scene", "Snapshot", "SnapshotBatch", "ampullary_angles",
           "build_plan", "coulomb_constant", "dipole_field", "empty_readings", "image_indices", "image_sources",
           "knollenorgan_angles", "monopole_field", "mormyromast_angles", "sensor_frame"]
