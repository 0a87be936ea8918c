"""``efish bench train``: rates are positive, MFU below one, the timed pass has the configured shape."""

from __future__ import annotations

from efish.config import compose


def test_bench_train_reports_positive_rates_and_an_mfu_below_one():
    from efish.bench.train import bench_train, forward_flops

    assert forward_flops(10, 4, 2) == 2 * 10 * 4 + 2 * 4 * 4 + 12 * 4 * 4 + 2 * 4 * 2
    rows = bench_train(compose(["env.n_agents=2", "train.num_envs=2", "train.chunk=10", "train.rollout_steps=20"]),
                       (8,), rollout_steps=10)
    for r in rows:
        assert r["update_samples_per_s"] > 0 and r["rollout_env_steps_per_s"] > 0 and 0 < r["mfu"] < 1


def test_bench_times_the_configured_pass_shape():
    from efish.bench.train import timed_sequences

    paper = compose(["scale=paper"])  # 16 arenas x 4 agents x 16 chunks = 1024 sequences per minibatch
    assert timed_sequences(paper) == paper.train.micro_sequences == 256
    assert timed_sequences(compose(["scale=paper", "train.micro_sequences=5000"])) == 1024
    assert timed_sequences(compose(["scale=paper", "train.minibatches=8", "train.micro_sequences=5000"])) == 128
