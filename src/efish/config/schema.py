"""Typed config schemas: one dataclass per Hydra config group.

YAML files under ``config/`` only set values; the fields, their meaning and
their allowed ranges live here. Every field is declared with :func:`param`, so
its one-line doc and its range sit next to it and :func:`validate` can check a
whole tree and name the offending key.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from dataclasses import dataclass, field
from typing import Any


class ConfigError(ValueError):
    """A config value is unknown, mistyped or out of range (message is one line)."""


def param(default: Any, doc: str, *, lo: float | None = None, hi: float | None = None,
          choices: tuple | None = None, neutral: bool = False) -> Any:
    """Declare a config field with a one-line doc and an optional allowed range.

    ``neutral``: the value cannot change a training result (threads, how often
    to checkpoint, how far to train), so a checkpoint written under another
    value may be resumed (see :func:`result_neutral_keys`).
    """
    meta = {"doc": doc, "lo": lo, "hi": hi, "choices": choices, "neutral": neutral}
    if isinstance(default, (list, dict)):
        return field(default_factory=lambda: type(default)(default), metadata=meta)
    return field(default=default, metadata=meta)


def group(cls: type) -> Any:
    """Declare a nested config group with its defaults."""
    return field(default_factory=cls)


# ---------------------------------------------------------------- renamed keys
#: Group -> {deprecated key: its new name}. A deprecated key is a field that defaults to None; setting it (in YAML,
#: on the command line, in a recorded config) warns and sets the new key (:func:`apply_renamed_keys`). Each stays
#: for one release after its rename (CHANGELOG.md, "Deprecated").
RENAMED_KEYS: dict[str, dict[str, str]] = {
    "physics": {"agent_dipole_cm": "agent_dipole_coulomb_metre", "pellet_dipole_cm": "pellet_dipole_coulomb_metre"},
}


def apply_renamed_keys(obj: Any, path: str, renamed: dict[str, str]) -> None:
    """Move the value of each deprecated key of dataclass ``obj`` that is set to its new key, with a FutureWarning
    naming the new key; the deprecated key reads None afterwards.

    Setting both is a :class:`ConfigError`, recognised by the new key holding another value than its default (the
    schema cannot tell a default from the same value written out). FutureWarning, not DeprecationWarning: the
    keys are set by users of the command line and YAML files, and Python hides DeprecationWarning outside
    ``__main__``.
    """
    defaults = {f.name: f.default for f in dataclasses.fields(obj)}
    for old, new in renamed.items():
        value = getattr(obj, old)
        if value is None:
            continue
        if getattr(obj, new) != defaults[new]:
            raise ConfigError(f"{path}{old} and {path}{new} are both set: {old} is the deprecated name of {new}; "
                              f"set only {path}{new}")
        warnings.warn(f"{path}{old} is deprecated and will be removed in the next release: set {path}{new} instead",
                      FutureWarning, stacklevel=4)
        setattr(obj, new, value)
        setattr(obj, old, None)


def with_current_key_names(config: dict) -> dict:
    """A recorded config as a nested dict (a checkpoint's ``training_config``) with every deprecated key's value
    under its new name, as this version records it: a checkpoint written before a rename still resumes."""
    out = dict(config)
    for group, renamed in RENAMED_KEYS.items():
        if not isinstance(out.get(group), dict):
            continue
        values = dict(out[group])
        for old, new in renamed.items():
            if values.get(old) is not None and new not in values:
                values[new] = values[old]
            values[old] = None
        out[group] = values
    return out


# --------------------------------------------------------------------- physics
@dataclass
class PhysicsConfig:
    """Field sources, walls and the accuracy knobs of the field computation (docs/model/physics.md#field-sources)."""

    eps0: float = param(8.854e-12, "vacuum permittivity, F/m", lo=0.0)
    eod_charge_c: float = param(1.11e-15, "EOD monopole charge q, C", lo=0.0)
    eod_half_separation_cm: float = param(0.5, "EOD monopoles sit at +-this along the body axis, cm", lo=0.0, hi=1.0)
    agent_radius_cm: float = param(1.0, "agent body radius, cm: centres stay 2 radii apart and 1 from walls; "
                                   "induction radius; the sensors sit on this circle", lo=0.0)
    pellet_radius_cm: float = param(0.25, "pellet radius (induction, ray hits), cm", lo=0.0)
    agent_dipole_coulomb_metre: float = param(1.11e-23, "agent intrinsic dipole along body +x, C*m")
    pellet_dipole_coulomb_metre: float = param(1.11e-24, "pellet intrinsic dipole along pellet +y, C*m")
    susceptibility: float = param(-0.5, "chi of bodies in water (negative: insulator)", lo=-10.0, hi=10.0)
    softening_m: float = param(1e-5, "eps in |d|^2 + eps^2, m", lo=0.0, hi=1e-2)
    image_order: int = param(1, "wall image order: 0 none, 1 one mirror per wall, up to 3", lo=0, hi=3)
    image_scale: float = param(0.95, "scale of every image per reflection", lo=0.0, hi=1.0)
    emission: bool = param(True, "agents may emit EODs at all")
    intrinsic: bool = param(True, "intrinsic (always-on) dipoles of agents and pellets exist")
    induction: bool = param(True, "bodies are polarised by EOD fields (induced dipoles)")
    tolerance: float = param(1e-7, "skip a source when a bound on its field is below tolerance * E_min; 0 = exact", lo=0.0, hi=1e3)
    dtype: str = param("float64", "floating type of the field kernels", choices=("float64", "float32"))
    error_bound: bool = param(False, "report a bound of every Mormyromast and Ampullary reading's error "
                              "(RawReadings.error_bound); off by default: it adds about 15% to sensing time",
                              neutral=True)
    far_field_levels: list = param([13, 31], "point counts (odd, increasing) a distant source may be interpolated "
                                   "from; the first is evaluated densely over all sources; [] = off")
    far_field_min_cm: float = param(3.0, "sources closer than this are always evaluated at every sensor, cm", lo=1.0)
    far_field_safety: float = param(100.0, "C in the interpolation error model C * Q * B * (r/D)^((Q+1)/2)", lo=1.0)
    # The old names of the two dipole moments (`_cm` read as centimetres, but they are C*m): they still work for
    # one release, with a FutureWarning; __post_init__ moves their value to the new key.
    agent_dipole_cm: float | None = param(None, "deprecated: the old name of agent_dipole_coulomb_metre (C*m, not "
                                          "cm); setting it warns and sets that key")
    pellet_dipole_cm: float | None = param(None, "deprecated: the old name of pellet_dipole_coulomb_metre (C*m, not "
                                           "cm); setting it warns and sets that key")

    def __post_init__(self) -> None:
        apply_renamed_keys(self, "physics.", RENAMED_KEYS["physics"])


# --------------------------------------------------------------------- sensors
@dataclass
class MormyromastConfig:
    """Active electroreceptors: distortions of EOD fields (docs/model/sensors.md#mormyromasts)."""

    enabled: bool = param(True, "compute and report this receptor class")
    count: int = param(36, "number of sensors", lo=1, hi=1024)
    chin_count: int = param(10, "sensors on the chin arc", lo=0, hi=1024)
    chin_half_angle_deg: float = param(30.0, "chin arc spans +-this from the heading, degrees", lo=0.0, hi=180.0)
    e_min: float = param(5e-8, "lower end of the log range, V/m", lo=0.0)
    e_max: float = param(5e-2, "upper end of the log range, V/m", lo=0.0)
    g_self: float = param(1.0, "gate on the own-EOD image part (0 or 1)", choices=(0.0, 1.0))
    g_cons: float = param(1.0, "gate on the conspecific-EOD image part (0 or 1)", choices=(0.0, 1.0))
    k_cons: float = param(100.0, "gain on the cons part when silent or g_self = 0", lo=0.0)
    wall_distortion: bool = param(False, "add the own EOD's wall images to the self part")


@dataclass
class AmpullaryConfig:
    """Passive electroreceptors: intrinsic fields of bodies (docs/model/sensors.md#ampullary-organs)."""

    enabled: bool = param(True, "compute and report this receptor class")
    count: int = param(24, "number of sensors, evenly spaced from the heading", lo=1, hi=1024)
    e_min: float = param(2e-10, "lower end of the log range, V/m", lo=0.0)
    e_max: float = param(2e-8, "upper end of the log range, V/m", lo=0.0)


@dataclass
class KnollenorganConfig:
    """Conspecific-EOD receptors, binarised per slot (docs/model/sensors.md#knollenorgans)."""

    enabled: bool = param(True, "compute and report this receptor class")
    count: int = param(12, "sensors per conspecific slot, evenly spaced", lo=1, hi=1024)
    threshold: float = param(2e-7, "|E.n| above this reads sign(E.n), V/m", lo=0.0)
    range_cm: float = param(100.0, "conspecifics whose centre is this close are in Knollenorgan range (steps "
                            "column n_agents_100cm, a decoding target; the authors' 100 cm); sensing is not cut "
                            "at it, cm", lo=0.0, neutral=True)


@dataclass
class NoiseConfig:
    """Multiplicative sensor noise (docs/model/sensors.md#noise)."""

    enabled: bool = param(True, "multiply raw readings by uniform noise")
    low: float = param(0.95, "lower factor for every raw reading", lo=0.0)
    high: float = param(1.05, "upper factor for every raw reading", lo=0.0)
    interference_low: float = param(0.0, "lower ampullary factor while a conspecific emits", lo=0.0)
    interference_high: float = param(2.0, "upper ampullary factor while a conspecific emits", lo=0.0)


@dataclass
class SensorsConfig:
    """Receptor classes, their layout, ranges, gates and noise (docs/model/sensors.md)."""

    perception: str = param("electric", "electric fields or the ray-casting baseline", choices=("electric", "raycast"))
    mormyromast: MormyromastConfig = group(MormyromastConfig)
    ampullary: AmpullaryConfig = group(AmpullaryConfig)
    knollenorgan: KnollenorganConfig = group(KnollenorganConfig)
    noise: NoiseConfig = group(NoiseConfig)
    ray_count: int = param(36, "ray casting: rays at the Mormyromast angles (first ray_count of them)", lo=1, hi=1024)
    ray_length_cm: float = param(100.0, "ray casting: ray length, cm", lo=0.0)


# ----------------------------------------------------------------------- arena
@dataclass
class ArenaConfig:
    """Arena size and food layout (docs/model/environment.md#arenas-and-food). ``layout=training`` samples size, layout
    and food multiplier per episode from the ``train_*`` fields."""

    layout: str = param("patchy", "food layout",
                        choices=("patchy", "uniform", "npatch", "onepatch", "training", "none"))
    width_cm: float = param(70.0, "arena width, cm", lo=4.0, hi=10000.0)
    height_cm: float = param(70.0, "arena height, cm", lo=4.0, hi=10000.0)
    food_multiplier: float = param(1.0, "scales food: uniform density, patchy patch count, npatch pellets", lo=0.0, hi=100.0)
    uniform_density: float = param(0.0045, "uniform: Poisson mean pellets per cm^2", lo=0.0)
    uniform_cap_density: float = param(0.005, "uniform: at most round(this * area) pellets", lo=0.0)
    patch_density: float = param(0.001, "patchy: max(1, round(multiplier * ceil(this * area))) patches", lo=0.0)
    patch_radius_mean_cm: float = param(6.0, "patchy: patch radius mean, cm", lo=0.0)
    patch_radius_sd_cm: float = param(1.5, "patchy: patch radius sd, cm", lo=0.0)
    patch_radius_min_cm: float = param(1.0, "patchy: patch radius lower clip, cm (upper: min(W, H) / 2)", lo=0.0)
    patch_pellet_density: float = param(0.15, "patchy and npatch: Poisson mean pellets per cm^2 of a patch", lo=0.0)
    patch_cap_density: float = param(0.2, "patchy: at most round(this * pi r^2) pellets per patch", lo=0.0)
    npatch_count: int = param(1, "npatch: number of patches n", lo=1, hi=64)
    npatch_radius_cm: float = param(7.5, "npatch: patch radius, cm", lo=0.0)
    npatch_ring_fraction: float = param(0.75, "npatch: ellipse semi-axes as a fraction of W/2 and H/2", lo=0.0, hi=1.0)
    onepatch_radius_cm: float = param(6.0, "onepatch: radius of the central patch, cm", lo=0.0)
    onepatch_initial_mean: float = param(11.3, "onepatch: Poisson mean pellets at the start", lo=0.0)
    onepatch_regrow_mean: float = param(1.13, "onepatch: Poisson mean pellets regrown per step", lo=0.0)
    onepatch_cap: int = param(34, "onepatch: regrowth stops at this many pellets", lo=0)
    train_size_min_cm: float = param(40.0, "training: W, H = min + span * u^exponent, u ~ U(0, 1)", lo=4.0)
    train_size_span_cm: float = param(260.0, "training: see train_size_min_cm", lo=0.0)
    train_size_exponent: float = param(3.0, "training: see train_size_min_cm", lo=0.0)
    train_patchy_weight: float = param(5.0, "training: odds of patchy against uniform, patchy part", lo=0.0)
    train_uniform_weight: float = param(1.0, "training: odds of patchy against uniform, uniform part", lo=0.0)
    train_none_weight: float = param(0.0, "training: odds of an arena without food (homing)", lo=0.0)
    train_multiplier_min: float = param(0.5, "training: food multiplier log-uniform in [min, max]", lo=0.0)
    train_multiplier_max: float = param(2.0, "training: see train_multiplier_min", lo=0.0)
    orientation_drift_rad: float = param(0.1, "pellet orientation random walk, sd per step, rad", lo=0.0)
    wall_margin_cm: float = param(1.0, "agents spawn at least this far from walls, cm", lo=0.0)


# ------------------------------------------------------------------------- env
@dataclass
class EnvConfig:
    """Bodies, motion, eating, biting, rewards and interventions of the foraging task (docs/model/physics.md#bodies,
    docs/model/environment.md)."""

    n_agents: int = param(4, "agents per environment", lo=1, hi=16)
    obs_agents: int = param(4, "observation layout is sized for this many agents (unused slots are 0)", lo=1, hi=16)
    episode_steps: int = param(1600, "steps before truncation", lo=1)
    fps: float = param(83.0, "steps per second (dt = 1/fps)", lo=1.0)
    speed_m_s: float = param(0.35, "v_max = speed * speed_gain * (1 + size), m/s", lo=0.0)
    speed_gain: float = param(2.0, "see speed_m_s", lo=0.0)
    turn_rad_s: float = param(3.6, "w_max = turn * turn_gain * (1 + size), rad/s", lo=0.0)
    turn_gain: float = param(4.0, "see turn_rad_s", lo=0.0)
    eat_radius_cm: float = param(2.0, "a pellet centre this close and within the eat angle is eaten", lo=0.0)
    eat_half_angle_deg: float = param(22.5, "eat zone: +-this from the heading, degrees", lo=0.0, hi=180.0)
    bite_radius_cm: float = param(3.0, "another agent this close and within the bite angle is bitten", lo=0.0)
    bite_half_angle_deg: float = param(22.5, "bite zone: +-this from the heading, degrees", lo=0.0, hi=180.0)
    eat_cooldown: int = param(3, "steps frozen after eating", lo=0)
    bite_cooldown: int = param(5, "steps before the next bite", lo=0)
    reward_food: float = param(10.0, "reward per pellet eaten")
    reward_shaping: float = param(1.0, "times (d_prev - d) / perimeter, d = distance to the nearest pellet")
    penalty_bitten: float = param(5.0, "bitten: -this * (1 + size_biter - size_victim)")
    penalty_bite: float = param(0.001, "cost of a successful bite")
    penalty_collision: float = param(0.5, "cost of a cancelled move")
    penalty_effort: float = param(0.1, "times max(0, |move| - free) + max(0, |turn| - free)")
    effort_free: float = param(0.5, "effort-free part of |move| and |turn|", lo=0.0)
    muted: list = param([], "agent ids that never emit")
    frozen: list = param([], "agent ids that never move or turn")
    sizes: list = param([], "fixed sizes per agent; empty = U(0, 1) per episode")
    starts: list = param([], "fixed starts per agent as [x_cm, y_cm, heading_rad]; empty = random")
    task: str = param("foraging", "reward and termination rules", choices=("foraging", "homing"))
    bots: list = param([], "agent ids driven by the bounded random-walk bot instead of the policy")
    bot_eod_rate: float = param(0.5, "bot: probability of an EOD each step", lo=0.0, hi=1.0)
    bot_radius_cm: float = param(8.5, "bot: random walk bounded in this circle around the arena centre", lo=0.0)
    homing_target: int = param(0, "homing: agent id of the frozen, always-emitting target", lo=0)
    homing_radius_cm: float = param(4.0, "homing: within this distance of the target counts as home", lo=0.0)
    homing_success_steps: int = param(5, "homing: consecutive steps at home that end the episode", lo=1)
    homing_reward_home: float = param(10.0, "homing: reward per step at home")
    homing_shaping: float = param(0.01, "homing: times (d_prev - d) / perimeter")
    homing_step_cost: float = param(0.05, "homing: cost per step")
    homing_min_distance_cm: float = param(0.0, "homing starts: every homer at least this far from the target, cm "
                                          "(the assay: 20)", lo=0.0)
    homing_clearance_cm: float = param(0.0, "homing starts: target and homers at least this far from every wall, "
                                       "cm (the assay: 5)", lo=0.0)
    roles: list = param([], "start placement per agent: random, resident (arena centre), intruder (facing the "
                        "resident from intruder_distance_cm), approach (facing the centre from one of "
                        "approach_distances_cm); empty = all random")
    intruder_distance_cm: list = param([20.0, 100.0], "intruder: [min, max] start distance from the resident, cm")
    approach_distances_cm: list = param([25.0, 50.0], "approach: start distances from the arena centre, one drawn "
                                        "per episode, cm")


# ----------------------------------------------------------------------- train
@dataclass
class TrainConfig:
    """Recurrent MAPPO (docs/methods/training.md#mappo). The sizes (hidden, epochs, num_envs, rollout_steps, chunk,
    total_steps) read the scale by interpolation, so their one copy is in :class:`ScaleConfig` and config/scale/*.yaml;
    a resolved config (:func:`~efish.config.compose`) holds numbers."""

    hidden: int = param("${scale.hidden}", "width of every layer and of the GRU", lo=1, hi=8192)
    head_gain: float = param(0.01, "orthogonal init gain of the output heads", lo=0.0)
    lr: float = param(5e-4, "Adam learning rate (actor and critic)", lo=0.0, hi=1.0)
    adam_eps: float = param(1e-5, "Adam epsilon", lo=0.0)
    weight_decay: float = param(1e-6, "Adam weight decay", lo=0.0)
    epochs: int = param("${scale.epochs}", "PPO epochs per update", lo=1)
    minibatches: int = param(1, "minibatches per epoch (split over sequences)", lo=1)
    micro_sequences: int = param(256, "sequences per forward/backward pass; a minibatch's gradients are summed "
                                      "over these micro-batches before its one optimiser step (same update, "
                                      "cache-sized work)", lo=1)
    clip: float = param(0.2, "PPO ratio clip and value clip", lo=0.0, hi=1.0)
    entropy_coef: float = param(0.01, "entropy bonus", lo=0.0)
    value_coef: float = param(1.0, "value loss weight", lo=0.0)
    huber_delta: float = param(10.0, "Huber loss delta of the value loss", lo=0.0)
    max_grad_norm: float = param(10.0, "gradient norm clip", lo=0.0)
    gamma: float = param(0.995, "discount", lo=0.0, hi=1.0)
    gae_lambda: float = param(0.95, "GAE lambda", lo=0.0, hi=1.0)
    num_envs: int = param("${scale.num_envs}", "parallel arenas per rollout", lo=1)
    rollout_steps: int = param("${scale.rollout_steps}", "steps per rollout", lo=1)
    chunk: int = param("${scale.chunk}", "BPTT chunk length; must divide rollout_steps", lo=1)
    total_steps: int = param("${scale.train_steps}", "env steps per seed (arena steps x arenas); a longer run "
                             "resumes a shorter one's checkpoint", lo=1, neutral=True)
    checkpoint_every: int = param(10, "updates between checkpoints", lo=1, neutral=True)
    keep_stages: list = param("${scale.keep_stages}", "fractions of the run (in (0, 1], increasing) at which to "
                              "keep the policy as stage_<k>.pt beside checkpoint.pt: the first update whose env "
                              "steps reach that fraction of the run's, always checkpointed; [] = none",
                              neutral=True)
    threads: int = param(1, "torch threads", lo=1, hi=256, neutral=True)
    loggers: list = param(["csv"], "where each update's metrics row also goes as it is made, besides "
                          "metrics.parquet: csv (metrics.csv), tensorboard (tensorboard/; needs the tensorboard "
                          "extra); [] = neither", choices=("csv", "tensorboard"), neutral=True)
    precision: str = param("auto", "arithmetic of the update's forward passes: fp32, bf16 autocast, or auto (time "
                           "the training GEMM in both once per machine, take the faster; recorded in provenance.json)",
                           choices=("auto", "fp32", "bf16"))
    bf16_speedup: float = param(1.2, "auto takes bf16 only when its GEMM runs at least this many times as fast as "
                                "fp32 (near ties keep fp32's numerics)", lo=1.0, neutral=True)
    device: str = param("cpu", "where the networks and the PPO update run (cuda: a GPU node); a resumed run may "
                        "switch", choices=("cpu", "cuda"), neutral=True)
    seed: int = param(1, "training seed", lo=0)

    def total_updates(self) -> int:
        """The updates a run makes: ``total_steps`` in whole rollouts of ``rollout_steps`` x ``num_envs``, at
        least one."""
        return max(1, self.total_steps // (self.rollout_steps * self.num_envs))


# ----------------------------------------------------------------------- assay
@dataclass
class AssayConfig:
    """An evaluation assay (docs/methods/assays.md): which conditions, how many episodes, how to act."""

    name: str = param("patchy4", "assay name, used in output paths")
    episodes: int = param(30, "episodes per condition", lo=1)
    seed: int = param(1000, "seed of the evaluation episodes (held out from training)", lo=0)
    deterministic: bool = param(True, "thresholded EOD/bite and Gaussian means instead of samples")
    policy: str = param("selected", "which trained policy acts: the selected foraging seed, or a policy recipe of "
                                    "config/policy/ (homing, homing_raycast); a condition may set its own")
    conditions: dict = param({}, "condition name -> list of config overrides (set by each assay file)")
    record_hidden: bool = param(False, "also write hidden.parquet: the policy's GRU state per step and agent")


# ----------------------------------------------------------------------- bench
@dataclass
class BenchConfig:
    """Sizes of the benchmarks (``efish bench ...``); a command's flags, where it has them, override these."""

    scenes: int = param(64, "benchmark snapshots (4-agent 70x70 patchy)", lo=1)
    repeats: int = param(7, "timing repeats; the fastest is reported (this VM is noisy)", lo=1)
    reference_scenes: int = param(8, "snapshots timed with the brute-force reference", lo=1)
    reference_rounds: int = param(3, "rounds of fast and reference runs in turn, for their ratio (best of each)",
                                  lo=1)
    tolerances: list = param([0.0, 1e-11, 1e-9, 1e-8, 1e-7, 1e-6, 1e-5, 1e-3, 1e-1, 1.0], "tolerances swept")
    image_orders: list = param([0, 1, 2, 3], "wall image orders swept")
    dtypes: list = param(["float64", "float32"], "kernel dtypes swept")
    softenings_m: list = param([1e-5, 1e-4, 1e-3], "softening lengths swept, m")
    seed: int = param(0, "seed of the benchmark scenes", lo=0)
    scaling_sizes_cm: list = param([70.0, 140.0, 280.0, 560.0], "bench scaling: square arena sides at the "
                                   "configured food density (the first is also the base of the other sweeps), cm")
    scaling_crowded_multiplier: float = param(10.0, "bench scaling: food multiplier of the crowded case in the "
                                              "first arena (0: no crowded case)", lo=0.0, hi=100.0)
    scaling_agents: list = param([1, 2, 4, 8, 16], "bench scaling: agent counts swept in the first arena")
    scaling_n_agents: int = param(4, "bench scaling: agents per arena in the pellet sweep", lo=1, hi=16)
    scaling_envs: int = param(16, "bench scaling: arenas stepped together", lo=1)
    scaling_agent_steps: int = param(2048, "bench scaling: agent-steps per timed call of the fast path", lo=1)
    scaling_exact_agent_steps: int = param(64, "bench scaling: agent-steps per timed call at tolerance 0", lo=1)
    env_envs: int = param(16, "bench env: arenas stepped together (--envs)", lo=1)
    env_steps: int = param(100, "bench env: timed steps of the fast path (--steps)", lo=1)
    train_hidden: list = param([512, 64], "bench train: network widths timed (--hidden)")
    train_skip_below: float = param(0.25, "bench train: a precision whose training-shape GEMM runs below this "
                                    "fraction of the fastest precision's is not timed, and its row says why: a slow "
                                    "path (bf16 on a CPU without AVX-512 runs ~50x below fp32) would take hours on a "
                                    "paper-size update to confirm what train.precision=auto already decided; 0 times "
                                    "every precision", lo=0.0, hi=1.0)
    budget_minutes: float = param(10.0, "bench budget: wall time of each training run, minutes (--minutes)", lo=0.0)
    budget_hidden: list = param([64, 128], "bench budget: network widths trained (--hidden)")
    budget_seeds: int = param(2, "bench budget: seeds per width (--seeds)", lo=1)
    budget_jobs: int = param(2, "bench budget: runs at a time, one thread each (--jobs)", lo=1)
    group_assay: str = param("patchy4", "bench group: the assay whose first condition the policies run")
    group_sizes: list = param([1, 2, 4], "bench group: policies per group timed (--sizes)")
    group_episodes: int = param(6, "bench group: episodes per policy (--episodes)", lo=1)
    group_steps: int = param(400, "bench group: steps per episode (--steps)", lo=1)
    multipole_orders: list = param([4, 6, 8], "bench multipole: expansion orders compared (--orders)")
    multipole_width_cm: float = param(560.0, "bench multipole: square arena side of the scene, cm (--width)", lo=0.0)


@dataclass
class ScaleConfig:
    """How big a run is: smoke, laptop, study or paper (config/scale/)."""

    name: str = param("laptop", "name of the scale, used in output paths")
    seeds: int = param(4, "foraging seeds trained (seed_offset + 1 .. seed_offset + seeds)", lo=1)
    seed_offset: int = param(0, "the trained seeds start after this one: a second run with offset = seeds draws "
                             "a disjoint set of seeds of the same recipe, and its homing policies train with seed "
                             "seed_offset + 1 (how stable its verdicts are, docs/claims/results.md)", lo=0)
    hidden: int = param(64, "network width (train.hidden reads it)", lo=1, hi=8192)
    num_envs: int = param(8, "parallel arenas per rollout (train.num_envs reads it)", lo=1)
    rollout_steps: int = param(400, "steps per foraging rollout (train.rollout_steps reads it)", lo=1)
    chunk: int = param(50, "foraging BPTT chunk (train.chunk reads it)", lo=1)
    epochs: int = param(15, "PPO epochs per update (train.epochs reads it)", lo=1)
    train_steps: int = param(240_000, "foraging env steps per seed", lo=1)
    homing_steps: int = param(160_000, "homing env steps", lo=1)
    homing_rollout_steps: int = param(800, "steps per homing rollout", lo=1)
    max_episodes: int = param(8, "cap on the episodes per assay condition (the paper-scale counts of "
                              "docs/methods/assays.md)", lo=1)
    selection_episodes: int = param(8, "patchy4 episodes per seed for seed selection "
                                    "(docs/methods/training.md#seed-selection)", lo=1)
    max_episode_steps: int = param(100_000, "cap on an assay episode's length (the smoke scale shortens them)", lo=1)
    top_seeds: int = param(4, "the best-ranked seeds (the selected one first): the others rerun every claim's assays "
                           "for seeds_agree and the recipe's verdict over seeds, and all run the top_seed_assays "
                           "(supplement)", lo=0)
    top_seed_episodes: int = param(6, "cap on the episodes per assay condition of the top seeds' reruns (the "
                                   "selected seed's own assays run max_episodes): more seeds at fewer episodes "
                                   "decide the recipe's verdict better (docs/claims/index.md#the-recipes-verdict)",
                                   lo=1)
    top_seed_assays: list = param(["patchy4", "wide2", "square2"], "assays the top seeds run")
    homing_seeds: int = param(3, "independent training draws of the homing recipes (homing, homing_raycast) the "
                              "homing claims (C1-C3, C18) are decided over, at most max(1, top_seeds): draw 1 is the "
                              "run's own, draw k >= 2 trains both recipes again with train.seed seed_offset + k and "
                              "the k-th top seed reruns homing with it (2 extra trainings of homing_steps per draw); "
                              "ignored by a scale without the homing assay", lo=1)
    keep_stages: list = param([], "fractions of each seed's training at which it keeps its policy for the claims "
                              "along training (train.keep_stages reads it; [] = none)")
    learning: bool = param(False, "the claims along training (snakemake learning: the selected seed's assays, "
                           "analyses and claims at each kept stage) are part of the default target")
    stage_episodes: int = param(8, "cap on the episodes per assay condition at each kept stage before the last "
                                "(the last stage, the final policy, is the run's own assays)", lo=1)
    clip_assays: list = param(["homing", "patchy4", "wide2", "onepatch"], "assays whose first episode the report "
                              "shows as a clip (efish render), those of them the scale runs")
    assays: list = param(["homing", "patchy4", "uniform4", "wide2", "square2", "ablation4", "ablation1",
                          "collective", "mute", "npatch", "food_scarcity", "onepatch", "bot", "groupsize"],
                         "assays the pipeline runs (names of config/assay/*.yaml)")

    def seed_numbers(self) -> list[int]:
        """The foraging seeds trained: ``seed_offset + 1`` .. ``seed_offset + seeds``."""
        return list(range(self.seed_offset + 1, self.seed_offset + self.seeds + 1))


# -------------------------------------------------------------------- analysis
@dataclass
class AnalysisConfig:
    """Parameters of the analyses (docs/methods/analyses.md, ``efish analyze``); ms per step and rates in Hz follow
    ``env.fps``."""

    idi_bins: int = param(50, "IDI histogram: log-spaced bins", lo=1, hi=100_000)
    idi_lo_ms: float = param(10.0, "IDI histogram: lower edge, ms (> 0, below idi_hi_ms)", lo=0.0)
    idi_hi_ms: float = param(3000.0, "IDI histogram: upper edge, ms", lo=0.0)
    xmin_ms: float = param(12.0, "power-law fit: smallest IDI fitted, ms", lo=0.0)
    rate_window: int = param(20, "EOD rate: centred rolling mean of eod over this many steps", lo=1)
    rate_bins: int = param(15, "EOD rate vs distance: equal distance bins", lo=1, hi=100_000)
    agent_range_cm: float = param(150.0, "EOD rate vs nearest-agent distance: bins span 0 to this, cm", lo=0.0)
    food_range_cm: float = param(10.0, "EOD rate vs nearest-food distance: bins span 0 to this, cm", lo=0.0)
    wall_range_cm: float = param(10.0, "EOD rate vs wall distance: bins span 0 to this, cm", lo=0.0)
    min_samples: int = param(5, "EOD rate vs distance: bins with fewer steps are dropped", lo=1)
    peri_window: int = param(100, "peri-event EOD rate: steps before and after each event", lo=1)
    min_events: int = param(3, "peri-event EOD rate: agent-episodes with fewer events are left out", lo=1)
    facing_rad: float = param(math.pi / 4, "interaction labels: |heading - bearing to the partner| at most this "
                              "faces it, rad", lo=0.0, hi=math.pi)
    away_rad: float = param(3 * math.pi / 4, "interaction labels: at least this faces away, rad", lo=0.0, hi=math.pi)
    bout_cm: float = param(10.0, "a pair this close interacts: bouts, bite rate by class, EOD-rate advantage, cm",
                           lo=0.0)
    contact_cm: float = param(2.0, "a bout whose centres come this close is a contact, cm", lo=0.0)
    variance_fraction: float = param(0.9, "hidden states: PCs counted until they explain this fraction of the "
                                     "variance", lo=0.0, hi=1.0)
    subsample_fractions: list = param([0.05, 0.15, 0.25, 0.5, 0.75, 1.0], "unit subsampling: fractions of the "
                                      "hidden units kept, each in (0, 1]")
    subsample_draws: int = param(30, "unit subsampling: random draws per fraction", lo=1)
    decode_folds: int = param(5, "decoding: GroupKFold folds over episodes", lo=2)
    plsc_shifts: int = param(30, "PLSC: circular shifts of the null", lo=1)
    plsc_percentile: float = param(97.5, "PLSC: a component beats this percentile of the null to count", lo=0.0,
                                   hi=100.0)
    plsc_edges_cm: list = param([10.0, 100.0], "PLSC: distance bin edges, increasing (<= first, ..., > last), cm")
    plsc_null_draws: int = param(99, "PLSC shared dimensions and collapse (dynamics plsc, plsc_collapse): episode "
                                 "permutations of the episode-swap null per component", lo=1)
    plsc_label_swaps: int = param(256, "PLSC collapse: near/far label assignments of the permutation test (all "
                                  "2^episodes when that is no more)", lo=2)
    spectrogram_window: int = param(20, "wideband power: spectrogram window, steps", lo=1)
    spectrogram_overlap: int = param(10, "wideband power: overlap of consecutive windows, steps (< window)", lo=0)
    seed: int = param(0, "seed of unit subsampling, PLSC null shifts, permutations and windows, and Dunnett's "
                      "p-values", lo=0)
    real_fish_idis: str = param("", "CSV or Parquet of real-fish IDIs (column idi_ms); empty: none, and the IDI "
                                "tables say so in their reason column")
    # claims (docs/claims/index.md, ``efish claims``)
    claims_resamples: int = param(4000, "claims: bootstrap resamples of episodes for the intervals no test inverts "
                                  "(C5, C15; at 1,000 an endpoint moved by 11% of the interval's width between "
                                  "two resampling seeds, at 4,000 by 2%)", lo=1)
    claims_fit_resamples: int = param(200, "claims: unused, kept so that configs setting it still compose (C4's "
                                      "power law no longer refits per resample: its interval inverts its clustered "
                                      "test); to be removed in the next release", lo=1)
    claims_seed: int = param(0, "claims: seed of the bootstrap (with the claim's number, so reruns are identical)",
                             lo=0)
    claims_alpha: float = param(0.05, "claims: a test is significant at p below this", lo=0.0, hi=1.0)
    claims_aligned_rad: float = param(math.pi / 4, "homing alignment_episodes (claim C2): |error| within this of 0 "
                                      "or pi counts as aligned, rad", lo=0.0, hi=math.pi / 2)
    # The two margins below decided "no difference" parts before each part had its smallest effect of interest
    # (efish.claims.deltas). Nothing reads them now; they stay because every recorded config (conditions.parquet,
    # analysis_settings.parquet) of a run made before holds them, and a key the schema lacks cannot be read back.
    claims_margin_fraction: float = param(0.2, "claims, no longer read (each part's delta decides): the earlier "
                                          "equivalence margin, a fraction of the control's median; kept so that "
                                          "tables recorded with it can be read", lo=0.0)
    claims_margin_sd: float = param(0.5, "claims, no longer read (each part's delta decides): the earlier "
                                    "equivalence margin in pooled SDs; kept so that tables recorded with it can be "
                                    "read", lo=0.0)
    claims_ceiling_share: float = param(0.5, "claims: a condition that ate every pellet in at least this share of "
                                        "its episodes is at a ceiling: its food parts are not decidable", lo=0.0,
                                        hi=1.0)
    claims_event_window: list = param([-10, 10], "signalling peri_event_episodes (claim C6): lags (steps) of the "
                                      "EOD rate around an event")
    claims_baseline_window: list = param([-100, -50], "signalling peri_event_episodes (claim C6): lags (steps) of "
                                         "the baseline rate; within +-peri_window")
    claims_deff_fraction: float = param(0.5, "claims C17: D_eff / network width is below this when low-dimensional",
                                        lo=0.0, hi=1.0)
    claims_near_cm: float = param(10.0, "claims C21: a conspecific this close is near, cm", lo=0.0)
    claims_far_cm: float = param(100.0, "claims C21: a conspecific farther than this is far, cm", lo=0.0)
    claims_food_near_cm: float = param(5.0, "food this close is in range when food variables are decoded near vs "
                                       "far (dynamics food_decoding, Fig 6F, claim C19): the authors' Mormyromast "
                                       "food range, 5 cm", lo=0.0)
    claims_trend_alpha: float = param(0.05, "claims along training (efish claims-by-stage): a part's effect moves "
                                      "toward or away from the paper's sign when the z-test of its weighted slope "
                                      "on log10 env steps gives p below this", lo=0.0, hi=1.0)


# ----------------------------------------------------------------------- scene
@dataclass
class SceneConfig:
    """A field-map scene of Fig 1 and the sensing-range maps (``efish scene <name>``, files in config/scene/)."""

    name: str = param("", "scene name, used in output paths (scenes/<name>.parquet); set by each scene file")
    kind: str = param("field", "what is computed: field (EOD fields on a grid), sensing_range (how strongly each "
                      "receptor class of an emitting agent detects a pellet or an agent around it), sensors "
                      "(sensor positions on the body), food_layouts (pellets of the arena generators)",
                      choices=("field", "sensing_range", "sensors", "food_layouts"))
    arena_cm: list = param([60.0, 40.0], "arena [width, height], cm: where bodies may sit and, with walls, the "
                           "insulating walls")
    walls: bool = param(False, "mirror the sources in the arena's walls (physics.image_order, image_scale); "
                        "false: free space")
    window_cm: list = param([], "field grid [x0, x1, y0, y1], cm; empty: the whole arena")
    resolution_cm: float = param(0.5, "field grid spacing, cm", lo=1e-3)
    agents: list = param([[30.0, 20.0, 0.0, 1]], "agents as [x_cm, y_cm, heading_rad, emitting (0/1)]; the first "
                         "is the focal agent (sensors)")
    pellets: list = param([], "pellets as [x_cm, y_cm, orientation_rad]")
    range_cm: list = param([1.2, 200.0], "sensing_range: [nearest, farthest] target distance from the focal "
                           "agent's centre, cm (log-spaced)")
    range_points: int = param(60, "sensing_range: log-spaced target distances", lo=2, hi=10_000)
    bearings: int = param(72, "sensing_range: target bearings, evenly around the focal agent", lo=4, hi=10_000)
    targets: list = param(["pellet", "agent"], "sensing_range: targets placed around the focal agent (pellet: "
                          "Mormyromast, Ampullary; agent, emitting: all three classes)")
    layouts: list = param([], "food_layouts: one [name, override, ...] per layout, e.g. [patchy, arena=patchy70]: "
                          "the config overrides of its arena")
    seed: int = param(0, "food_layouts: seed of the arena and pellet draws", lo=0)


@dataclass
class EfishConfig:
    """The whole composed config."""

    physics: PhysicsConfig = group(PhysicsConfig)
    sensors: SensorsConfig = group(SensorsConfig)
    arena: ArenaConfig = group(ArenaConfig)
    env: EnvConfig = group(EnvConfig)
    train: TrainConfig = group(TrainConfig)
    assay: AssayConfig = group(AssayConfig)
    bench: BenchConfig = group(BenchConfig)
    scale: ScaleConfig = group(ScaleConfig)
    analysis: AnalysisConfig = group(AnalysisConfig)
    scene: SceneConfig = group(SceneConfig)


# Groups whose values a training run depends on; the rest (assay, bench, scale, analysis) only name or size other
# jobs, and what the scale sets for training reaches it through train.* (resolved).
TRAINING_GROUPS = ("physics", "sensors", "arena", "env", "train")


def result_neutral_keys(cfg: Any = None, path: str = "") -> set[str]:
    """Dotted keys declared ``neutral`` in the schema: a checkpoint written under other values still resumes."""
    cfg = cfg if cfg is not None else EfishConfig()
    keys = set()
    for f in dataclasses.fields(cfg):
        value = getattr(cfg, f.name)
        if dataclasses.is_dataclass(value):
            keys |= result_neutral_keys(value, f"{path}{f.name}.")
        elif f.metadata.get("neutral"):
            keys.add(f"{path}{f.name}")
    return keys


def training_config(cfg: "EfishConfig") -> dict:
    """The resolved values a training run depends on, as a plain nested dict (what a checkpoint records)."""
    return {g: dataclasses.asdict(getattr(cfg, g)) for g in TRAINING_GROUPS}


def config_differences(a: dict, b: dict, ignore: set[str] = frozenset(), path: str = "") -> list[str]:
    """Dotted keys whose values differ between two nested dicts (missing on one side counts), minus ``ignore``."""
    keys = []
    for k in sorted(set(a) | set(b)):
        key = f"{path}{k}"
        va, vb = a.get(k), b.get(k)
        if key in ignore:
            continue
        if isinstance(va, dict) and isinstance(vb, dict):
            keys += config_differences(va, vb, ignore, key + ".")
        elif va != vb or (k in a) != (k in b):
            keys.append(key)
    return keys


# ------------------------------------------------------------------ validation
def validate(obj: Any, path: str = "") -> None:
    """Check every field of a dataclass tree against its declared range or choices.

    Raises :class:`ConfigError` with a one-line message naming the full key.
    """
    for f in dataclasses.fields(obj):
        key = f"{path}{f.name}"
        value = getattr(obj, f.name)
        if dataclasses.is_dataclass(value):
            validate(value, key + ".")
            continue
        meta = f.metadata
        # a list field with choices (train.loggers) picks any of them: each item is checked
        is_list = isinstance(value, (list, tuple))
        items = value if is_list else [value]
        if meta.get("choices") is not None and any(item not in meta["choices"] for item in items):
            allowed = ", ".join(str(c) for c in meta["choices"])
            raise ConfigError(f"{key}={value!r} is not allowed: choose {'any' if is_list else 'one'} of {allowed}")
        lo, hi = meta.get("lo"), meta.get("hi")
        if (lo is not None and value < lo) or (hi is not None and value > hi):
            lo_s = "-inf" if lo is None else f"{lo:g}"
            hi_s = "inf" if hi is None else f"{hi:g}"
            raise ConfigError(f"{key}={value!r} is out of range: allowed [{lo_s}, {hi_s}]")
    _check_consistency(obj, path)


def _check_consistency(obj: Any, path: str) -> None:
    """Cross-field rules that a single range cannot express."""
    if isinstance(obj, AssayConfig) and not obj.conditions:
        raise ConfigError(f"{path}conditions is empty: an assay needs at least one condition")
    if isinstance(obj, TrainConfig) and obj.rollout_steps % obj.chunk:
        raise ConfigError(f"{path}chunk={obj.chunk} must divide {path}rollout_steps={obj.rollout_steps}")
    if isinstance(obj, TrainConfig):
        stages = list(obj.keep_stages)
        if (any(isinstance(f, bool) or not isinstance(f, (int, float)) or not 0 < f <= 1 for f in stages)
                or stages != sorted(set(stages))):
            raise ConfigError(f"{path}keep_stages={stages} must hold strictly increasing fractions in (0, 1]")
    if isinstance(obj, ScaleConfig) and obj.learning and not obj.keep_stages:
        raise ConfigError(f"{path}learning=true needs {path}keep_stages (the fractions of training to keep)")
    if isinstance(obj, EnvConfig):
        if obj.n_agents > obj.obs_agents:
            raise ConfigError(f"{path}n_agents={obj.n_agents} exceeds {path}obs_agents={obj.obs_agents} (observation slots)")
        for key in ("muted", "frozen", "bots"):
            bad = [i for i in getattr(obj, key) if not (isinstance(i, int) and 0 <= i < obj.n_agents)]
            if bad:
                raise ConfigError(f"{path}{key} has agent ids {bad} outside 0..{obj.n_agents - 1}")
        if obj.sizes and (len(obj.sizes) != obj.n_agents or any(not 0 <= v <= 1 for v in obj.sizes)):
            raise ConfigError(f"{path}sizes must hold {obj.n_agents} values in [0, 1]")
        if obj.task == "homing" and obj.homing_target >= obj.n_agents:
            raise ConfigError(f"{path}homing_target={obj.homing_target} is not an agent id (0..{obj.n_agents - 1})")
        if obj.starts and (len(obj.starts) != obj.n_agents or any(len(x) != 3 for x in obj.starts)):
            raise ConfigError(f"{path}starts must hold {obj.n_agents} entries [x_cm, y_cm, heading_rad]")
        roles = ("random", "resident", "intruder", "approach")
        if obj.roles and (len(obj.roles) != obj.n_agents or any(r not in roles for r in obj.roles)):
            raise ConfigError(f"{path}roles must hold {obj.n_agents} of {', '.join(roles)}, got {obj.roles}")
        if len(obj.intruder_distance_cm) != 2 or not 0 <= obj.intruder_distance_cm[0] <= obj.intruder_distance_cm[1]:
            raise ConfigError(f"{path}intruder_distance_cm must be [min, max] with 0 <= min <= max")
        if not obj.approach_distances_cm or min(obj.approach_distances_cm) < 0:
            raise ConfigError(f"{path}approach_distances_cm must hold at least one distance >= 0")
    if isinstance(obj, ArenaConfig):
        if obj.train_multiplier_min > obj.train_multiplier_max or obj.train_multiplier_min <= 0:
            raise ConfigError(f"{path}train_multiplier_min must be > 0 and <= {path}train_multiplier_max")
        if obj.train_patchy_weight + obj.train_uniform_weight + obj.train_none_weight <= 0:
            raise ConfigError(f"{path}train_patchy_weight, train_uniform_weight and train_none_weight sum to 0")
    if isinstance(obj, PhysicsConfig):
        levels = list(obj.far_field_levels)
        if any(q % 2 == 0 or not 3 <= q <= 63 for q in levels) or levels != sorted(set(levels)):
            raise ConfigError(f"{path}far_field_levels={levels} must hold increasing odd counts in [3, 63]")
    if isinstance(obj, AnalysisConfig):
        _check_analysis(obj, path)
    if isinstance(obj, SceneConfig):
        _check_scene(obj, path)
    if isinstance(obj, (MormyromastConfig, AmpullaryConfig)) and not 0 < obj.e_min < obj.e_max:
        raise ConfigError(f"{path}e_min={obj.e_min:g} must be > 0 and below {path}e_max={obj.e_max:g}")
    if isinstance(obj, MormyromastConfig) and obj.chin_count > obj.count:
        raise ConfigError(f"{path}chin_count={obj.chin_count} exceeds {path}count={obj.count}")
    if isinstance(obj, NoiseConfig):
        if obj.low > obj.high:
            raise ConfigError(f"{path}low={obj.low:g} exceeds {path}high={obj.high:g}")
        if obj.interference_low > obj.interference_high:
            raise ConfigError(f"{path}interference_low exceeds {path}interference_high")



def _check_analysis(obj: AnalysisConfig, path: str) -> None:
    """Cross-field rules of the analysis group."""
    if not 0 < obj.idi_lo_ms < obj.idi_hi_ms:
        raise ConfigError(f"{path}idi_lo_ms={obj.idi_lo_ms:g} must be > 0 and below "
                          f"{path}idi_hi_ms={obj.idi_hi_ms:g}")
    if obj.facing_rad > obj.away_rad:
        raise ConfigError(f"{path}facing_rad={obj.facing_rad:g} exceeds {path}away_rad={obj.away_rad:g}")
    if obj.spectrogram_overlap >= obj.spectrogram_window:
        raise ConfigError(f"{path}spectrogram_overlap={obj.spectrogram_overlap} must be below "
                          f"{path}spectrogram_window={obj.spectrogram_window}")
    if not obj.subsample_fractions or any(not 0 < f <= 1 for f in obj.subsample_fractions):
        raise ConfigError(f"{path}subsample_fractions={list(obj.subsample_fractions)} must hold values in (0, 1]")
    edges = list(obj.plsc_edges_cm)
    if edges != sorted(set(edges)) or any(e < 0 for e in edges):
        raise ConfigError(f"{path}plsc_edges_cm={edges} must be increasing distances >= 0")


def _check_scene(obj: SceneConfig, path: str) -> None:
    """Cross-field rules of the scene group: shapes of the arena, window and body lists."""
    if len(obj.arena_cm) != 2 or min(obj.arena_cm) <= 0:
        raise ConfigError(f"{path}arena_cm={list(obj.arena_cm)} must be [width, height] with both > 0")
    w = obj.window_cm
    if w and (len(w) != 4 or not (w[0] < w[1] and w[2] < w[3])):
        raise ConfigError(f"{path}window_cm={list(w)} must be [] or [x0, x1, y0, y1] with x0 < x1 and y0 < y1")
    if any(len(a) != 4 for a in obj.agents) or not obj.agents:
        raise ConfigError(f"{path}agents must hold at least one [x_cm, y_cm, heading_rad, emitting]")
    if any(len(p) != 3 for p in obj.pellets):
        raise ConfigError(f"{path}pellets must hold [x_cm, y_cm, orientation_rad] entries")
    if len(obj.range_cm) != 2 or not 0 < obj.range_cm[0] < obj.range_cm[1]:
        raise ConfigError(f"{path}range_cm={list(obj.range_cm)} must be [nearest, farthest] with 0 < nearest < farthest")
    names = [layout[0] for layout in obj.layouts if layout]
    if len(names) != len(obj.layouts) or len(set(names)) != len(names):
        raise ConfigError(f"{path}layouts must hold [name, override, ...] entries with distinct names")
    if any(t not in ("pellet", "agent") for t in obj.targets):
        raise ConfigError(f"{path}targets={list(obj.targets)} must name pellet or agent")
