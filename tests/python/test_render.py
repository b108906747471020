"""render: the same pixels as `volscissors render`, image orientation, progress and errors."""
import numpy as np
import pytest

import volscissors as vs
from conftest import cli, read_png


@pytest.mark.parametrize("mode, extra_cli, extra_py", [
    ("full", [], {}),
    ("mip", ["--view", "30,20"], {"view": (30, 20)}),
    ("triplanar", ["--planes", "20,30,40"], {"planes": (20, 30, 40)}),
])
def test_images_equal_the_cli(vessels, tmp_path, mode, extra_cli, extra_py):
    path, _ = vessels
    png = tmp_path / "cli.png"
    cli("render", path, "--mode", mode, "--size", "96x80", *extra_cli, "--out", png)
    ref = read_png(png)
    img = vs.render(vs.read(path), mode=mode, size=(96, 80), **extra_py)
    assert img.shape == (80, 96, 4) and img.dtype == np.uint8  # rows = height
    assert np.array_equal(img[..., :ref.shape[2]], ref)
    assert img[..., :3].max() > 0  # something was drawn


def test_progress_and_bad_arguments(vessels):
    v = vs.read(vessels[0])
    stages = []
    vs.render(v, size=(32, 32), progress=lambda f, s: stages.append(s))
    assert stages
    with pytest.raises(ValueError):
        vs.render(v, mode="holo")
    with pytest.raises(ValueError, match="size"):
        vs.render(v, size=(0, 10))
    with pytest.raises(ValueError):
        vs.render(v, tf="no-such-preset")
    with pytest.raises(OSError):
        vs.render(v, tf="/no/such/tf.json")
