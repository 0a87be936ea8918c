"""The effect plan: simulate only what the scene calls for.

The physics and sensors configs say which effects exist (physics switches,
receptor classes, gates); a :class:`Scene` says what the scene holds (how many
agents, whether any may emit, whether there are pellets). The simulator knows
no task: the environment (or ``efish.sense``, from a snapshot) describes the
scene, and :func:`build_plan` turns both into an :class:`EffectPlan` once per
episode. Kernels for absent effects are
not called at all, and every number the kernels need is derived here in SI
units, so kernels never see a config. ``efish plan <overrides>`` prints
:meth:`EffectPlan.explain`.

Culling rule (``tolerance``): for each agent, a source (a body or one of its
wall images) is skipped for a receptor class when a bound on its field at
every sensor of that agent is below ``tolerance * E_min`` of the class. The
bound for a dipole p at distance D from the agent centre, with sensors on a
circle of radius r, is 2 k |p| / (D - r)^3, exact for the worst direction. A
whole receptor array is skipped when the sum of the bounds of all its sources,
times the largest noise factor, stays at or below E_min: every normalised
reading is then exactly 0. With tolerance > 0, a distant source is evaluated
at Q points on the sensor circle and interpolated to the sensors, with the
smallest Q of ``far_field_levels`` whose error bound C Q B (r/D)^((Q+1)/2) stays
below the same ``tolerance * E_min`` (see :mod:`efish.physics.sense_kernel`).
``tolerance = 0`` computes every source at every sensor.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..config.schema import EfishConfig
from ..units import CM
from .far_field import far_field_tables
from .fields import coulomb_constant, polarisability
from .geometry import ampullary_angles, knollenorgan_angles, mormyromast_angles
from .images import image_indices, image_weights


@dataclass(frozen=True)
class Scene:
    """What a scene holds, as far as the fields care.

    The defaults describe a scene with every effect the config allows: several
    agents, emitters and pellets. ``efish.env`` derives it from the task and
    the interventions; :meth:`of_batch` from given snapshots.
    """

    agents: int = 2        # agents per arena (1: no conspecific channels)
    emitters: bool = True  # some agent may emit an EOD (False: no induction, no Knollenorgan spikes)
    pellets: bool = True   # some pellet may exist (False: no pellet loops)

    @classmethod
    def of_batch(cls, batch) -> "Scene":
        """The scene of known snapshots (a :class:`~efish.physics.snapshot.SnapshotBatch`)."""
        return cls(agents=int(batch.shape[1]), emitters=bool(np.any(batch.agent_emitting)),
                   pellets=bool(np.any(batch.pellet_alive)))


@dataclass(frozen=True)
class Effect:
    """One effect of the simulation: whether it runs and why."""

    name: str
    on: bool
    why: str


@dataclass(frozen=True, eq=False)  # identity equality: plans key caches of kernel inputs
class EffectPlan:
    """Which kernels run and every derived constant they need (SI units)."""

    effects: tuple[Effect, ...]
    dtype: str
    tolerance: float
    # sources
    eps0: float                 # vacuum permittivity, F/m (the reference's closed-form fields)
    k: float                    # 1 / (4 pi eps0), V m / C
    eod_charge: float           # C
    eod_half_separation: float  # m
    agent_dipole: float         # C m, body +x
    pellet_dipole: float        # C m, pellet +y
    alpha_agent: float          # induced moment per field, C m / (V/m)
    alpha_pellet: float
    softening2: float           # m^2
    image_indices: np.ndarray   # int64[I, 2], identity first
    image_weights: np.ndarray   # float64[I]
    image_scale: float
    # sensors
    sensor_radius: float        # m
    morm_angles: np.ndarray     # rad[36]
    amp_angles: np.ndarray      # rad[24]
    knollen_angles: np.ndarray  # rad[12]
    far_levels: tuple[int, ...]  # point counts Q of the far-field levels; () = off
    far_min: float              # m; closer sources are always exact
    far_safety: float           # C of the error model C * Q * B * (r/D)^((Q+1)/2)
    far_tables: np.ndarray      # [L, 2, Qmax] cos, sin of each level's point angles
    morm_interp: np.ndarray     # [L, 36, Qmax] level points -> Mormyromast angles
    amp_interp: np.ndarray      # [L, 24, Qmax] level points -> Ampullary angles
    morm_range: tuple[float, float]
    amp_range: tuple[float, float]
    knollen_threshold: float
    g_self: float
    g_cons: float
    k_cons: float
    noise: bool
    noise_range: tuple[float, float]
    interference_range: tuple[float, float]
    notes: tuple[str, ...] = field(default=())

    def on(self, name: str) -> bool:
        """Whether the named effect runs."""
        for e in self.effects:
            if e.name == name:
                return e.on
        raise KeyError(f"no effect named {name!r}; effects are {[e.name for e in self.effects]}")

    @property
    def max_noise(self) -> float:
        """Largest factor noise can multiply a Mormyromast or Knollenorgan reading by."""
        return self.noise_range[1] if self.noise else 1.0

    @property
    def max_amp_noise(self) -> float:
        """Largest factor noise can multiply an Ampullary reading by."""
        return max(self.noise_range[1], self.interference_range[1]) if self.noise else 1.0

    def explain(self) -> str:
        """Human-readable table of effects and why each is in or out."""
        width = max(len(e.name) for e in self.effects)
        lines = [f"effect plan (dtype {self.dtype}, tolerance {self.tolerance:g}, "
                 f"{len(self.image_weights) - 1} wall images per source)"]
        lines += [f"  [{'x' if e.on else ' '}] {e.name:<{width}}  {e.why}" for e in self.effects]
        lines += [f"  note: {n}" for n in self.notes]
        return "\n".join(lines)


def build_plan(cfg: EfishConfig, scene: Scene | None = None, *, tolerance: float | None = None,
               dtype: str | None = None) -> EffectPlan:
    """Decide which effects run for ``scene`` under ``cfg.physics`` and ``cfg.sensors``; derive the kernel constants.

    No pellets -> no pellet loops; nobody can emit -> no induction and no
    Knollenorgan spikes; a lone agent -> no conspecific channels. ``scene``
    defaults to :class:`Scene` (every effect the config allows).
    """
    ph, se = cfg.physics, cfg.sensors
    scene = scene or Scene()
    agents = scene.agents
    tol = ph.tolerance if tolerance is None else float(tolerance)
    if not tol >= 0:
        raise ValueError(f"tolerance must be >= 0, got {tolerance}")
    electric = se.perception == "electric"
    pellets = scene.pellets
    emitters = ph.emission and scene.emitters
    m_on, a_on, k_on = (electric and se.mormyromast.enabled, electric and se.ampullary.enabled,
                        electric and se.knollenorgan.enabled)
    gates_open = se.mormyromast.g_self > 0 or se.mormyromast.g_cons > 0
    walls = ph.image_order > 0 and ph.image_scale > 0

    def why_receptor(name: str, enabled: bool) -> str:
        if not electric:
            return "off: perception is ray casting, no fields are computed"
        return "on" if enabled else f"off: sensors.{name}.enabled is false (ablated, reads 0)"

    effects = (
        Effect("fields", electric, "electric perception" if electric else "off: ray-casting baseline replaces all fields"),
        Effect("mormyromast", m_on, why_receptor("mormyromast", se.mormyromast.enabled)),
        Effect("ampullary", a_on, why_receptor("ampullary", se.ampullary.enabled)),
        Effect("knollenorgan", k_on and emitters and agents > 1,
               "off: no conspecifics" if agents < 2 else
               ("off: nobody can emit, every spike is 0" if k_on and not emitters else why_receptor("knollenorgan", se.knollenorgan.enabled))),
        Effect("eod_emission", emitters, "agents may emit" if emitters else "off: physics.emission false or no agent of the scene may emit"),
        Effect("induction", m_on and emitters and ph.induction and gates_open,
               "induced dipoles feed Mormyromasts" if m_on and emitters and ph.induction and gates_open else
               "off: " + ("no Mormyromasts" if not m_on else "no emitters" if not emitters else
                          "physics.induction is false" if not ph.induction else "both gates closed")),
        Effect("self_part", m_on and se.mormyromast.g_self > 0, f"g_self = {se.mormyromast.g_self:g}"),
        Effect("cons_part", m_on and se.mormyromast.g_cons > 0 and agents > 1,
               f"g_cons = {se.mormyromast.g_cons:g}" + ("" if agents > 1 else ", but no conspecifics")),
        Effect("wall_distortion", m_on and emitters and se.mormyromast.wall_distortion and walls and se.mormyromast.g_self > 0,
               "own EOD wall images added to the self part" if se.mormyromast.wall_distortion and se.mormyromast.g_self > 0
               else "off: sensors.mormyromast.wall_distortion is false" if not se.mormyromast.wall_distortion
               else "off: the self part is gated out (g_self = 0)"),
        Effect("intrinsic_fields", a_on and ph.intrinsic, "intrinsic dipoles feed Ampullary organs" if a_on and ph.intrinsic else
               "off: " + ("no Ampullary organs" if not a_on else "physics.intrinsic is false")),
        Effect("pellets", pellets, "pellet sources in the loops" if pellets else "off: the scene has no pellets"),
        Effect("wall_images", electric and walls, f"image order {ph.image_order}, scale {ph.image_scale:g}" if walls else "off: image order 0 or scale 0"),
        Effect("noise", electric and se.noise.enabled, "multiplicative, seeded" if se.noise.enabled else "off: sensors.noise.enabled is false"),
        Effect("culling", electric and tol > 0, f"sources below {tol:g} x E_min skipped" if tol > 0 else "off: tolerance 0 computes every source"),
        Effect("far_field", electric and tol > 0 and len(ph.far_field_levels) > 0,
               f"distant sources interpolated from {list(ph.far_field_levels)} points on the sensor circle"
               if tol > 0 and ph.far_field_levels else "off: " + ("tolerance 0" if tol == 0 else "physics.far_field_levels is empty")),
        Effect("error_bound", electric and ph.error_bound,
               "each reading's error bound is summed over culled and interpolated sources" if ph.error_bound
               else "off: physics.error_bound is false"),
    )
    k = coulomb_constant(ph.eps0)
    order = ph.image_order if walls else 0
    idx = image_indices(order)
    return EffectPlan(
        effects=effects, dtype=dtype or ph.dtype, tolerance=tol,
        eps0=ph.eps0, k=k, eod_charge=ph.eod_charge_c, eod_half_separation=ph.eod_half_separation_cm * CM,
        agent_dipole=ph.agent_dipole_coulomb_metre, pellet_dipole=ph.pellet_dipole_coulomb_metre,
        alpha_agent=polarisability(ph.agent_radius_cm * CM, ph.susceptibility, ph.eps0),
        alpha_pellet=polarisability(ph.pellet_radius_cm * CM, ph.susceptibility, ph.eps0),
        softening2=ph.softening_m ** 2,
        image_indices=idx, image_weights=image_weights(idx, ph.image_scale), image_scale=ph.image_scale,
        sensor_radius=ph.agent_radius_cm * CM,  # the sensors sit on the body circle
        morm_angles=mormyromast_angles(se.mormyromast), amp_angles=ampullary_angles(se.ampullary),
        knollen_angles=knollenorgan_angles(se.knollenorgan),
        far_min=ph.far_field_min_cm * CM, far_safety=ph.far_field_safety,
        **far_field_tables(tuple(ph.far_field_levels) if tol > 0 else (),
                           mormyromast_angles(se.mormyromast), ampullary_angles(se.ampullary)),
        morm_range=(se.mormyromast.e_min, se.mormyromast.e_max),
        amp_range=(se.ampullary.e_min, se.ampullary.e_max),
        knollen_threshold=se.knollenorgan.threshold,
        g_self=se.mormyromast.g_self, g_cons=se.mormyromast.g_cons, k_cons=se.mormyromast.k_cons,
        noise=electric and se.noise.enabled,
        noise_range=(se.noise.low, se.noise.high),
        interference_range=(se.noise.interference_low, se.noise.interference_high),
    )
