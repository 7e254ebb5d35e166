"""The growing-domain proof: a conservation law solved on a mesh that moves with the interior field."""

import numpy as np
import pytest

pytest.importorskip("skfem")

from morphomap.examples import growing_kidney  # noqa: E402


def test_mass_is_conserved_and_no_triangle_inverts():
    result = growing_kidney.run(steps=10)
    masses = result["masses"]
    assert np.abs(masses / masses[0] - 1).max() < 1e-3  # the bar; the scheme keeps it exactly
    assert result["inverted"] == 0 and result["smallest_area"] > 0
    # Something happened: the blob spread out (its peak fell) on a domain that grew.
    assert result["concentration"].max() < 0.9


@pytest.mark.parametrize("dim", [2, 3])
def test_eq2_in_dolfinx_keeps_the_mass_across_the_frames(tmp_path, dim):
    # morphomap makes the motion (frames mapped, extended on one moving mesh, a series XDMF);
    # dolfinx, in the system Python, solves Eq. 2 on the mesh it reads with its defaults.
    import json
    import os
    import subprocess

    import matplotlib.image

    from conftest import require_client
    from morphomap.examples import growing_domain_fenicsx, growing_frames

    python = "/usr/bin/python3"
    available = os.path.exists(python) and subprocess.run(
        [python, "-c", "import dolfinx, h5py, matplotlib"], capture_output=True).returncode == 0
    require_client(available, "FEniCSx (python3-dolfinx, python3-h5py) with matplotlib")
    interiors = growing_frames.prepare(tmp_path, dim=dim)
    assert len(interiors) == 4 and all(i.inverted == 0 for i in interiors)
    done = subprocess.run([python, growing_domain_fenicsx.__file__, str(tmp_path)], capture_output=True, text=True,
                          timeout=600, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    got = json.loads(done.stdout.strip().splitlines()[-1])
    assert got["steps"] == 4 and len(got["masses"]) == 4 * got["substeps"] + 1
    assert got["drift"] < 1e-10 and got["masses"][0] > 0
    assert got["peak"] < 0.9  # the blob spread out on the growing domain
    image = matplotlib.image.imread(tmp_path / "concentration.png")[..., :3]
    assert (np.abs(image - image[0, 0]).max(axis=2) > 0.05).mean() > 0.05
    assert (tmp_path / "concentration.xdmf").exists() and (tmp_path / "concentration.h5").exists()
