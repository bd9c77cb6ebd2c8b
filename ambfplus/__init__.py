"""ambfplus: surgical simulation with ground-truth data, a C++ engine scripted from Python.

Conventions (SI units; world frame right-handed, z up):

- ``Camera.pose`` is world-from-camera in the OpenCV camera frame (x right, y down, z forward).
- ``Frame.rgb`` is uint8 (H, W, 3) RGB, ``Frame.depth`` float32 (H, W) metric z along the optical
  axis, 0 where nothing was hit; image row 0 is the top.
- ``Camera.intrinsics``: fx = fy = H / (2 tan(fov_y / 2)), cx = W / 2, cy = H / 2, where pixel
  (row r, column c) is centred at (c + 0.5, r + 0.5). Subtract 0.5 from cx and cy for tools that
  put pixel centres on integers (OpenCV).
"""

try:
    from . import _core  # noqa: F401 (fail here with a clear message)
except ImportError as _error:  # pragma: no cover - depends on how the package was found
    import glob as _glob
    import os as _os

    if _glob.glob(_os.path.join(_os.path.dirname(__file__), "_core*.so")):
        raise  # the engine is there but does not load: the original error says why
    raise ImportError(
        f"ambfplus was imported from {_os.path.dirname(__file__)}, which holds no compiled engine "
        "(ambfplus._core). Install the package (pip install .) and run from outside the source "
        "folder, or use the installed command (ambfplus ...)."
    ) from _error

from ._core import (
    ActuatorHold,
    ArgumentError,
    ArgumentTypeError,
    AssetNotFound,
    Axis,
    Camera,
    ConfigError,
    ConstraintActuator,
    ControlOutput,
    Device,
    DistanceField,
    Drill,
    DrillSound,
    Error,
    Frame,
    InputDevice,
    Joint,
    JointType,
    JoystickDevice,
    JoystickMapping,
    KeyboardDevice,
    Label,
    Light,
    LightType,
    LoadReport,
    MergedDevice,
    MeshCollision,
    Model,
    NetworkDevice,
    NotFound,
    NullDevice,
    Object,
    OpenXrSession,
    OutOfRange,
    PluginError,
    PluginInfo,
    ProximitySensor,
    RealTimeLoop,
    RemovalMode,
    RenderError,
    ReplayDevice,
    ResourceError,
    RigidBody,
    ScriptedDevice,
    ShapeKind,
    SimulatedDevice,
    Simulator,
    SkillMetrics,
    SoftBody,
    StateError,
    Volume,
    VolumeData,
    World,
    __version__,
    gl_info,
    load_nrrd,
    load_slice_stack,
    openxr_built,
    phantom,
    read_colors,
    read_input_devices,
    read_label_table,
    read_launch,
    render_drill_sound,
    write_image,
    write_label_table,
)
from .devices import input_device_options
from .plugin import Plugin, cmake_dir, plugin_dir
from .transforms import make_pose, rotation_between, rpy_matrix
from .volumes import convert_volume, load_volume

__all__ = [
    "__version__",
    "ActuatorHold",
    "ArgumentError",
    "ArgumentTypeError",
    "AssetNotFound",
    "Axis",
    "Camera",
    "cmake_dir",
    "ConfigError",
    "ConstraintActuator",
    "ControlOutput",
    "convert_volume",
    "Device",
    "DistanceField",
    "Drill",
    "DrillSound",
    "Error",
    "Frame",
    "gl_info",
    "input_device_options",
    "InputDevice",
    "Joint",
    "JointType",
    "JoystickDevice",
    "JoystickMapping",
    "KeyboardDevice",
    "Label",
    "Light",
    "LightType",
    "load_nrrd",
    "load_slice_stack",
    "load_volume",
    "LoadReport",
    "make_pose",
    "MergedDevice",
    "MeshCollision",
    "Model",
    "NetworkDevice",
    "NotFound",
    "NullDevice",
    "Object",
    "openxr_built",
    "OpenXrSession",
    "OutOfRange",
    "phantom",
    "Plugin",
    "plugin_dir",
    "PluginError",
    "PluginInfo",
    "ProximitySensor",
    "read_colors",
    "read_input_devices",
    "read_label_table",
    "read_launch",
    "RealTimeLoop",
    "RemovalMode",
    "render_drill_sound",
    "RenderError",
    "ReplayDevice",
    "ResourceError",
    "RigidBody",
    "rotation_between",
    "rpy_matrix",
    "ScriptedDevice",
    "ShapeKind",
    "SimulatedDevice",
    "Simulator",
    "SkillMetrics",
    "SoftBody",
    "StateError",
    "Volume",
    "VolumeData",
    "World",
    "write_image",
    "write_label_table",
]
