"""Every output array of a few reference runs is bit for bit what it was when
tests/golden/hashes.json was recorded (tests/golden/cases.py says how): a refactoring
that changes one rounding anywhere shows here, long before it shows in a tolerance.

The same bits on every machine: the cases run again in fresh processes that take the
kernels another CPU would get (OpenBLAS's kernel choice, glibc's libm variants without
FMA, numpy's SIMD loops without AVX-512) and must match the same hashes
(docs/development.md, "Bit for bit")."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from golden.cases import CASES, differences, simulate_case

HERE = Path(__file__).parent
EXPECTED = json.loads((HERE / "golden" / "hashes.json").read_text())

# Each line is a machine this one can pass for: OpenBLAS's kernels by name; glibc's libm
# without its FMA variants (CPUs before Haswell, low-end Pentium/Celeron); numpy's loops
# without AVX-512, or at its baseline.
OTHER_MACHINES = {
    "haswell": {"OPENBLAS_CORETYPE": "Haswell"},
    "skylakex": {"OPENBLAS_CORETYPE": "SkylakeX", "NPY_DISABLE_CPU_FEATURES": "X86_V3 X86_V4 AVX512_ICL"},
    "prescott_without_fma": {
        "OPENBLAS_CORETYPE": "Prescott",
        "GLIBC_TUNABLES": "glibc.cpu.hwcaps=-AVX2,-FMA,-FMA4,-AVX512F",
        "NPY_DISABLE_CPU_FEATURES": "X86_V4 AVX512_ICL",
    },
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_outputs_bit_for_bit(name, paper_run):
    ds = paper_run if name == "paper_step" else simulate_case(name)
    arrays, attrs = differences(name, ds, EXPECTED)
    assert not arrays, f"{name}: arrays changed: {arrays}"
    assert not attrs, f"{name}: attributes changed: " + ", ".join(attrs)


@pytest.mark.skipif(
    sys.platform != "linux" or os.uname().machine != "x86_64",
    reason="the kernel names are x86-64 OpenBLAS's and glibc's",
)
@pytest.mark.parametrize("machine", sorted(OTHER_MACHINES))
def test_same_bits_with_another_cpus_kernels(machine):
    env = {
        k: v
        for k, v in os.environ.items()
        if k not in ("OPENBLAS_CORETYPE", "GLIBC_TUNABLES", "NPY_DISABLE_CPU_FEATURES")
    }
    env.update(OTHER_MACHINES[machine])
    run = subprocess.run(
        [sys.executable, str(HERE / "golden" / "cases.py"), "--check"],
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 0, f"{machine} ({OTHER_MACHINES[machine]}):\n{run.stdout}{run.stderr[-2000:]}"
