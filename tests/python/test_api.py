"""The sph Python package over the build's libsph.so: fields as numpy arrays
(shapes, dtypes, the t = 0 state of the twisting column against its
lattice and initial twist), stepping, energies, the summary, files written
into a temporary folder, and errors as sph.Error naming the key."""

import json
import math
import re

import numpy as np
import pytest

import sph

# the twisting column (scenes/twisting_column.yaml) on 5 x 13 x 5 particles,
# two milliseconds: a few dozen steps
COUNT = (5, 13, 5)
SMALL = {"bodies.0.particles.count": list(COUNT), "time.end": 0.002, "output.every": 0.001}
N = COUNT[0] * COUNT[1] * COUNT[2]


def column(scenes, **kw):
    kw.setdefault("threads", 1)
    return sph.load(scenes / "twisting_column.yaml", set=dict(SMALL, **kw.pop("more", {})), **kw)


def lattice():
    # the box [-0.5, 0.5] x [0, 6] x [-0.5, 0.5], faces included
    x = np.linspace(-0.5, 0.5, COUNT[0])
    y = np.linspace(0.0, 6.0, COUNT[1])
    z = np.linspace(-0.5, 0.5, COUNT[2])
    return np.array([(a, b, c) for a in x for b in y for c in z])


def rows(a):
    return a[np.lexsort(a.T[::-1])]


def test_version():
    assert re.fullmatch(r"\d+\.\d+\.\d+", sph.version())


def test_fields_at_rest_lattice(scenes):
    with column(scenes, no_files=True) as run:
        assert run.name == "twisting_column"
        assert run.end_time == pytest.approx(0.002)
        assert run.time == 0.0 and run.steps == 0 and run.state == "going"
        assert run.particles == N
        f = run.fields()
        for name in ("position", "velocity", "displacement", "pressure", "von_mises", "J", "body"):
            assert name in f, name
        for name, a in f.items():
            assert a.dtype == np.float64, name
            assert a.shape == ((N, 3) if sph.FIELDS[name] == 3 else (N,)), name
            assert np.all(np.isfinite(a)), name
            assert not a.flags.writeable
        # views of the library's arrays, not copies
        assert np.shares_memory(f["position"], run.field("position"))
        assert not np.shares_memory(f["position"], run.field("position", copy=True))
        # t = 0: the particles on the scene's lattice, undeformed (J = 1, no
        # displacement, no pressure), one body
        np.testing.assert_allclose(rows(f["position"]), lattice(), atol=1e-12)
        np.testing.assert_allclose(f["displacement"], 0.0, atol=1e-12)
        np.testing.assert_allclose(f["J"], 1.0, atol=1e-12)
        np.testing.assert_allclose(f["pressure"], 0.0, atol=1e-6)
        assert np.all(f["body"] == 0)
        # the initial twist: v = omega(y) x r, omega = (0, 105 sin(pi y / 12), 0)
        x, y, z = f["position"].T
        w = 105.0 * np.sin(np.pi * y / 12.0)
        np.testing.assert_allclose(f["velocity"], np.column_stack([w * z, 0 * w, -w * x]), atol=1e-9)
        e = run.energy()
        assert math.isfinite(e.kinetic) and math.isfinite(e.strain)
        assert e.kinetic > 1e5  # 3.4 MJ on the paper's lattice
        assert e.strain == pytest.approx(0.0, abs=1e-9)
    s = run.summary
    assert s.state == "stopped" and s.t == 0.0 and s.steps == 0


def test_advance_updates_fields(scenes):
    run = column(scenes, no_files=True)
    x0 = run.field("position", copy=True)
    e0 = run.energy()
    assert run.advance(0.001) == "going"
    assert run.time == pytest.approx(0.001, abs=1e-15)
    steps = run.steps
    assert steps > 0
    f = run.fields()
    assert not np.array_equal(f["position"], x0)
    # the displacement is the motion from the lattice, the twist strains it
    np.testing.assert_allclose(f["displacement"], f["position"] - x0, atol=1e-12)
    assert np.max(np.abs(f["J"] - 1.0)) > 0.0
    assert np.max(np.abs(f["J"] - 1.0)) < 0.05
    assert np.max(f["von_mises"]) > 0.0
    e1 = run.energy()
    assert e1.strain > 0.0
    # a conservative method over a millisecond: total energy within 1 %
    assert e1.kinetic + e1.strain == pytest.approx(e0.kinetic + e0.strain, rel=0.01)
    # to the end time (None), then the advance stays there
    assert run.advance() == "completed"
    assert run.time == pytest.approx(0.002, abs=1e-15)
    assert run.advance(1.0) == "completed"
    s = run.close()
    assert s is run.summary and run.closed
    assert s.state == "completed" and s.stable and s.verdict == "stable"
    assert s.t == pytest.approx(0.002, abs=1e-15) and s.steps > steps
    assert s.method == "tl-jst" and s.reference
    assert run.close() is s
    with pytest.raises(sph.Error):
        run.fields()


def test_files_into_a_folder(scenes, tmp_path):
    out = tmp_path / "run"
    more = {"output.every": 0.001, "output.png.width": 160, "output.png.height": 90}
    with column(scenes, out=out, more=more) as run:
        assert run.advance() == "completed"
    s = run.summary
    assert s.state == "completed" and s.out_dir.rstrip("/").endswith("run")
    summary = json.loads((out / "summary.json").read_text())
    assert summary["stable"] is True and summary["particles"] == N
    names = sorted(p.name for p in out.iterdir())
    assert len([n for n in names if n.endswith(".vtp")]) == 3, names
    assert "energy.csv" in names and "probes.csv" in names, names
    assert len(list((out / "frames").glob("*.png"))) == 3
    # an earlier run's folder: refused, then replaced with overwrite=True
    with pytest.raises(sph.Error):
        column(scenes, out=out, more=more)
    with column(scenes, out=out, more=more, overwrite=True) as run:
        run.advance()
    assert run.summary.state == "completed"


def test_bad_key_raises(scenes):
    with pytest.raises(sph.Error) as e:
        sph.load(scenes / "twisting_column.yaml", set={"time.ned": 1})
    assert "time.ned" in e.value.key
    assert e.value.status == "SPH_ERR_UNKNOWN_KEY"
    assert "time.ned" in str(e.value)


def test_bad_value_and_file(scenes, tmp_path):
    with pytest.raises(sph.Error) as e:
        sph.load(scenes / "twisting_column.yaml", set=["time.end=-1"])
    assert e.value.key == "time.end"
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: bad\ndimension: 3\ntime: {end: [\n")
    with pytest.raises(sph.Error) as e:
        sph.load(bad)
    assert e.value.file.endswith("bad.yaml") and e.value.line > 0
    with pytest.raises(sph.Error):
        sph.load(tmp_path / "missing.yaml")


def test_unsupported_field(scenes):
    with column(scenes, no_files=True) as run:
        with pytest.raises(sph.Error) as e:
            run.field("temperature")
        assert e.value.code != 0


def test_request_stop(scenes):
    # a stop asked before advancing: the run stops at the first step
    # boundary, stays there, and closes as stopped
    with column(scenes, no_files=True) as run:
        run.request_stop()
        assert run.advance() == "stopped"
        assert run.time < run.end_time
        t = run.time
        assert run.advance() == "stopped" and run.time == t
    assert run.summary.state == "stopped"


def test_request_stop_named_in_summary(scenes, tmp_path):
    # a stop asked from Python is no signal: summary.json says "request"
    out = tmp_path / "stopped"
    with column(scenes, out=out) as run:
        run.request_stop()
        assert run.advance() == "stopped"
    summary = json.loads((out / "summary.json").read_text())
    assert summary["stopped_by"] == "request"
    assert summary["completed"] is False
