"""The CPU-against-GPU table of workflow/gpu-check.sh: rows matched by width and precision, the end-to-end ratio,
and one-line errors for files that cannot be compared."""

from __future__ import annotations

import json

import pytest

from efish.bench.devices import main, side_by_side

CPU = [{"hidden": 512, "precision": "fp32", "auto": True, "update_samples_per_s": 1000.0,
        "end_to_end_env_steps_per_s": 40.0, "cpu": "AMD EPYC", "cpu_capability": "AVX2"},
       {"hidden": 512, "precision": "bf16", "auto": False, "update_samples_per_s": None,
        "end_to_end_env_steps_per_s": None, "cpu": "AMD EPYC", "cpu_capability": "AVX2"}]
# on the GPU auto takes bf16 (listed first here: rows are matched by width and precision, not by order)
GPU = [{**CPU[1], "auto": True, "update_samples_per_s": 9000.0, "end_to_end_env_steps_per_s": 120.0, "gpu": "G"},
       {**CPU[0], "auto": False, "update_samples_per_s": 5000.0, "end_to_end_env_steps_per_s": 100.0, "gpu": "G"}]


def test_rows_are_matched_by_width_and_precision_and_the_ratio_is_end_to_end():
    lines = side_by_side(CPU, GPU).splitlines()
    assert lines[0] == "CPU: AMD EPYC (torch CPU capability AVX2); GPU: G"
    fp32, bf16 = lines[2].split(), lines[3].split()
    assert fp32 == ["512", "fp32", "1,000", "5,000", "40.0", "100.0", "2.50x"]  # 100 / 40, not 5,000 / 1,000
    assert bf16 == ["512", "bf16", "-", "9,000", "-", "120.0", "-"]  # not timed on the CPU: no ratio
    # what training gains: each device at its own auto precision, CPU fp32 against GPU bf16
    assert lines[-1] == ("width 512, as train.precision=auto trains: CPU fp32 40.0, GPU bf16 120.0 env-steps/s "
                         "end to end: 3.00x")


def test_benchmarks_of_other_rows_cannot_be_compared():
    with pytest.raises(ValueError, match="did not time the same widths and precisions"):
        side_by_side(CPU, [{**GPU[0], "hidden": 64}, GPU[1]])
    with pytest.raises(ValueError, match="did not time the same"):
        side_by_side([], [])


def test_the_command_prints_the_table_or_one_line(tmp_path, capsys):
    cpu, gpu = tmp_path / "cpu.json", tmp_path / "gpu.json"
    cpu.write_text(json.dumps(CPU))
    gpu.write_text(json.dumps(GPU))
    assert main([str(cpu), str(gpu)]) == 0 and "2.50x" in capsys.readouterr().out
    gpu.write_text(json.dumps([{"hidden": 512}]))
    assert main([str(cpu), str(gpu)]) == 2
    assert capsys.readouterr().err == "efish bench devices: error: a row lacks the field 'precision'\n"
    assert main([str(cpu), str(tmp_path / "none.json")]) == 2
    assert capsys.readouterr().err.count("\n") == 1
