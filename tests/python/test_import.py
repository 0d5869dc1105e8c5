"""The installed package (tools/install-python.sh): Debian's python3 imports it from any
folder with no PYTHONPATH, and it is the package of this build."""
import os
import pathlib
import subprocess

import portalsim


def test_import_anywhere_without_pythonpath(tmp_path):
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    code = ("import portalsim, portalsim.torch; print(portalsim.__version__); print(portalsim._core.__file__); "
            "print(portalsim.Generator(seed=1).batch(0, 4)['metal'].shape)")
    r = subprocess.run(["/usr/bin/python3", "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True)
    assert r.returncode == 0, f"import portalsim failed (run tools/install-python.sh):\n{r.stderr}"
    version, where, shape = r.stdout.split("\n")[:3]
    assert version == portalsim.__version__
    assert shape == "(4, 19)"
    # The installed module is this build's, file for file.
    installed, built = pathlib.Path(where).parent, pathlib.Path(portalsim._core.__file__).parent
    for f in sorted(built.glob("*.py")) + [pathlib.Path(portalsim._core.__file__)]:
        assert (installed / f.name).read_bytes() == f.read_bytes(), \
            f"{installed / f.name} differs from the build's {f}: run tools/install-python.sh"
