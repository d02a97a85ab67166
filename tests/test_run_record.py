"""A run's record (rbm_cli.numerics.records): its kind refuses a name given twice, and a
run sets every field of its kind before the loop reads it (compiled, a field never set
would be read as garbage)."""

from __future__ import annotations

import pytest

import rbm
from rbm_cli.models.rbm.step.work import PLANE
from rbm_cli.models.rbm3d.work import COLUMN3D
from rbm_cli.numerics import records
from rbm_cli.numerics.records import record_fields, record_kind

COLUMN = {"height": 5.0, "base_width": 0.96, "top_width": 0.66, "density": 2700,
          "drums": 2, "section": "circular"}  # fmt: skip


def test_a_name_given_twice_is_refused_by_name():
    with pytest.raises(TypeError, match=r"repeat a name: \['a'\]$"):
        record_kind([("a", "float64"), ("b", "int64"), ("a", "float64[::1]")])


class _Watched:
    """A plain record that keeps the names of the fields set on it."""

    made: list = []

    def __init__(self):
        object.__setattr__(self, "names", set())
        _Watched.made.append(self)

    def __setattr__(self, name, value):
        self.names.add(name)
        object.__setattr__(self, name, value)


@pytest.mark.parametrize(("model", "kind", "excitation"), [
    ("rbm", PLANE, {"type": "harmonic", "duration": 1.0}),
    ("rbm-3d", COLUMN3D, {"type": "harmonic", "duration": 1.0, "angle": 30.0}),
])  # fmt: skip
def test_a_run_sets_every_field_of_its_record(monkeypatch, model, kind, excitation):
    monkeypatch.setattr(records, "SimpleNamespace", _Watched)
    monkeypatch.setattr(_Watched, "made", [])
    cfg = rbm.load_config({
        "name": "r", "model": model, "column": COLUMN,
        "interface": {"stiffness": {"normal": 5e9}, "restitution": 0.9},
        "excitation": excitation, "solver": {"implementation": "python", "rtol": 1e-8},
    })  # fmt: skip
    rbm.run(cfg, amplitude_g=0.6, frequency_hz=1.5)
    assert len(_Watched.made) == 1
    assert _Watched.made[0].names == set(record_fields(kind))
