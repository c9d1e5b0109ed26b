"""design-v1 files: round trip, defaults, extras kept, one-line errors naming the field."""

import json

import numpy as np
import pytest

from metainterface.errors import MetainterfaceError
from metainterface.physics import Design


def write(tmp_path, data, name="d.json"):
    path = tmp_path / name
    path.write_text(data if isinstance(data, str) else json.dumps(data))
    return path


def test_round_trip_keeps_extras_and_defaults(tmp_path):
    src = write(tmp_path, {"gamma": [2.0] * 4, "h": [0, 0.001, 0.002, 0.003], "note": {"a": 1}})
    d = Design.load(src)
    assert d.settings.n_asperities == 4 and d.settings.delta_max == 0.02
    assert d.extras == {"note": {"a": 1}}
    out = d.save(tmp_path / "out" / "d2.json")
    again = Design.load(out)
    np.testing.assert_array_equal(again.h, d.h)
    data = json.loads(out.read_text())
    assert data["format"] == "metainterface/design-v1" and data["note"] == {"a": 1}
    assert "version" in data["provenance"]
    assert not list(out.parent.glob(".*tmp"))  # no temporary left behind


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ("{not json", "malformed JSON at line 1"),
        ([1, 2], "JSON object"),
        ({"h": [0.0]}, "missing required field 'gamma'"),
        ({"gamma": [2.0] * 9, "h": [0.0] * 8}, "same length"),
        ({"gamma": [2.0] * 8, "h": [0.0] * 8}, "perfect square"),
        ({"gamma": [2.0, 2.0, 2.0, 0.9], "h": [0.0] * 4}, r"gamma\[3\] = 0.9 is outside"),
        ({"gamma": [2.0, 2.0, 2.0, 4.5], "h": [0.0] * 4}, r"bounds \[1.8, 4\]"),
        ({"gamma": [2.0] * 4, "h": [0.0, -1e-3, 0, 0]}, r"h\[1\] = -0.001 is negative"),
        ({"gamma": [2.0] * 4, "h": [0.0, "x", 0, 0]}, r"h\[1\] must be a number"),
        ({"gamma": [2.0] * 4, "h": [0.0, 0, 0, float("nan")]}, r"h\[3\] is nan"),
        ({"gamma": [2.0] * 4, "h": [0.0] * 4, "format": "other/v9"}, "unknown format"),
        ({"gamma": [2.0] * 4, "h": [0.0] * 4, "gamma_bounds": [3, 2]}, "gamma_min < gamma_max"),
        ({"gamma": [2.0] * 4, "h": [0.0] * 4, "delta_max": 0}, "delta_max must be > 0"),
    ],
)
def test_bad_files(tmp_path, data, message):
    with pytest.raises(MetainterfaceError, match=message):
        Design.load(write(tmp_path, data))


def test_design_has_its_delta_max_and_plain_ints():
    import numpy as np

    from metainterface.physics.cell import CellSettings, Design

    d = Design(gamma=[2.0] * 4, h=[0.0] * 4, settings=CellSettings(n_asperities=np.int64(4)))
    assert d.delta_max == d.settings.delta_max == 0.02
    assert type(d.settings.n_asperities) is int and "np." not in repr(d.settings)
    assert type(d.n_asperities) is int
