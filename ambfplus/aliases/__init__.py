"""Top-level modules under other projects' names, for scripts written against those projects.

Each module here is installed at the wheel's top level as well (CMakeLists.txt), where it stands
for an ambfplus module: ``ambf_client`` is ``ambfplus.ambf_client``."""
