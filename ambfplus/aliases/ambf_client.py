"""``import ambf_client``: AMBF's client module name, standing for ``ambfplus.ambf_client``.

The wheel installs this file at its top level (CMakeLists.txt), so that a script written for
AMBF's Python client (``from ambf_client import Client``) runs unchanged. The module replaces
itself with ``ambfplus.ambf_client``: one set of classes, whichever name imported them."""

import sys

import ambfplus.ambf_client as client

sys.modules[__name__] = client
