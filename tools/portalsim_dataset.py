"""The data.h5 loader now lives in the package: portalsim.torch.H5Dataset (docs/guide/python.md).

This name stays for scripts that import it from tools/:
    from portalsim_dataset import PortalsimDataset   # the same class as portalsim.torch.H5Dataset
Needs the package installed (tools/install-python.sh).
"""
from portalsim.torch import H5Dataset as PortalsimDataset  # noqa: F401
