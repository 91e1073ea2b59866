"""The processor a run measured: speed figures depend on it as much as on the code.

The same generated code and the same Pinocchio gave different ratios on two machines of the
same kind (docs/performance-log.md, 29 November: an AMD EPYC with Zen 4 cores, then an Intel
Xeon of Emerald Rapids), so every report names its processor. Standard library only.
"""

import os
import platform


def _cpuinfo():
    """The first processor's fields of /proc/cpuinfo ({} where there is none)."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            text = f.read()
    except OSError:
        return {}
    fields = {}
    for line in text.split("\n\n", 1)[0].splitlines():
        key, sep, value = line.partition(":")
        if sep:
            fields[key.strip()] = value.strip()
    return fields


def describe():
    """`model name, N CPUs, widest SIMD` of this machine, e.g.
    `Intel(R) Xeon(R) Processor (family 6 model 207), 2 CPUs, AVX-512`."""
    info = _cpuinfo()
    name = info.get("model name") or platform.processor() or platform.machine() or "unknown"
    if "cpu family" in info and "model" in info:
        name += f" (family {info['cpu family']} model {info['model']})"
    flags = set(info.get("flags", "").split())
    simd = ("AVX-512" if "avx512f" in flags else "AVX2" if "avx2" in flags
            else "AVX" if "avx" in flags else None)
    parts = [name, f"{os.cpu_count() or 1} CPUs"] + ([simd] if simd else [])
    return ", ".join(parts)
