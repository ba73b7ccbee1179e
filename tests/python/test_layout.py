"""The ctypes mirror of the public structures (python/sph/_capi.py) has the
C compiler's sizes and offsets: tests/python/layout.c prints them (ctest
passes its path in SPH_LAYOUT_PROBE)."""

import ctypes
import json
import os
import subprocess

import pytest

from sph import _capi

PROBE = os.environ.get("SPH_LAYOUT_PROBE")


@pytest.mark.skipif(not PROBE, reason="SPH_LAYOUT_PROBE not set (ctest sets it)")
@pytest.mark.parametrize(
    "cname, mirror",
    [
        ("sph_error", _capi.Error_t),
        ("sph_run_options", _capi.RunOptions_t),
        ("sph_summary", _capi.Summary_t),
    ],
)
def test_struct_layout(cname, mirror):
    c = json.loads(subprocess.run([PROBE], check=True, capture_output=True, text=True).stdout)[cname]
    assert ctypes.sizeof(mirror) == c.pop("size"), "%s changed size: update _capi.py" % cname
    py = {name: getattr(mirror, name).offset for name, _ in mirror._fields_}
    assert py == c


@pytest.mark.skipif(not PROBE, reason="SPH_LAYOUT_PROBE not set (ctest sets it)")
def test_enums():
    c = json.loads(subprocess.run([PROBE], check=True, capture_output=True, text=True).stdout)
    assert c["enum"] == ctypes.sizeof(ctypes.c_int)
    assert c["state_count"] == len(_capi.STATES)
