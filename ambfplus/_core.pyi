"""
ambfplus engine bindings (use the ambfplus package, not this module)
"""
from __future__ import annotations
import collections.abc
import numpy
import numpy.typing
import os
import typing
class Error(Exception):
    """Every error the engine raises."""
class ArgumentError(Error, ValueError):
    """A value a caller gave cannot be used."""
class ConfigError(Error, ValueError):
    """A bad scene or data file; .filename names it."""
class PluginError(Error, RuntimeError):
    """A plugin failed to load or to run."""
class RenderError(Error, RuntimeError):
    """Rendering failed or cannot start (what is missing is named)."""
class ResourceError(Error, OSError):
    """A socket, port or device file that cannot be used."""
class StateError(Error, RuntimeError):
    """A call that does not fit the object's state."""
class AssetNotFound(Error, FileNotFoundError):
    """A missing file; .filename names it, .tried lists every place looked."""
class NotFound(Error, KeyError):
    """A name or key that names nothing where it was looked up."""
class OutOfRange(Error, IndexError):
    """An index outside what it indexes."""
class ArgumentTypeError(ArgumentError, TypeError):
    """A value of the wrong type, or a keyword option that does not exist."""
__all__: list[str] = ['ActuatorHold', 'ArgumentError', 'ArgumentTypeError', 'AssetNotFound', 'Axis', 'Camera', 'ConfigError', 'ConstraintActuator', 'ControlOutput', 'DRILL_SOUND_MAX_WARNINGS', 'Device', 'DistanceField', 'Drill', 'DrillSound', 'Error', 'Frame', 'InputDevice', 'Joint', 'JointType', 'JoystickDevice', 'JoystickMapping', 'KeyboardDevice', 'Label', 'Light', 'LightType', 'LiveMetrics', 'LoadReport', 'MAX_ANTIALIASING', 'MergedDevice', 'MeshCollision', 'Model', 'NetworkDevice', 'NotFound', 'NullDevice', 'Object', 'OpenXrSession', 'OutOfRange', 'PLUGIN_ABI_VERSION', 'PluginError', 'PluginInfo', 'PluginSite', 'ProximitySensor', 'RealTimeLoop', 'RemovalMode', 'RenderError', 'ReplayDevice', 'ResourceError', 'RigidBody', 'ScriptedDevice', 'ShapeKind', 'SimulatedDevice', 'Simulator', 'SkillMetrics', 'SoftBody', 'StateError', 'Volume', 'VolumeData', 'Window', 'World', 'burr_in_volume', 'capture_passes', 'gl_info', 'live_metrics', 'load_nrrd', 'load_slice_stack', 'openxr_built', 'phantom', 'plugin_search_path', 'read_colors', 'read_input_devices', 'read_label_table', 'read_launch', 'render_drill_sound', 'use_x11_display', 'write_image', 'write_label_table']
class Window:
    """
    An X11 window (GLFW's, made without a client API) showing cameras.
    """
    def __init__(self, x11_window: typing.SupportsInt | typing.SupportsIndex) -> None:
        """
        Wraps the X11 window with this id (GLFW's glfwGetX11Window()).
        """
    def present(self, cameras: collections.abc.Sequence[Camera], width: typing.SupportsInt | typing.SupportsIndex, height: typing.SupportsInt | typing.SupportsIndex, overlay: typing.Any = None, rendered: bool = False) -> list:
        """
        Renders the cameras side by side into the window (width x height pixels), blends the RGBA overlay over them and shows it (GIL released); returns each view's camera, step and time. rendered=True shows what the cameras last rendered for a display (an OpenXR session's end_frame) without rendering again.
        """
    def set_lens(self, k: typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(4)"] | None, aberration: typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(3)"] = [1.0, 1.0, 1.0], centres: collections.abc.Sequence[typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(2)"]] = [], radius: typing.SupportsFloat | typing.SupportsIndex = 0.5, aspect: typing.SupportsFloat | typing.SupportsIndex = 1.0) -> None:
        """
        Undoes a head-mounted display's lens distortion on every view from now on (k: the PanoTools coefficients a, b, c, d; a window pixel at r from its view's lens centre shows the image at r (a r^3 + b r^2 + c r + d); r in units of radius, a fraction of the view's width; centres: each view's lens centre as fractions of its viewport, y from the bottom; aspect: the view's physical width / height). k=None shows plain images.
        """
class OpenXrSession:
    """
    A session with the OpenXR runtime's head-mounted display, given the engine's EGL context (XR_MNDX_egl_enable). Per frame: poll_events(); while running: eyes = wait_frame(), place a camera per eye, end_frame(cameras). Raises RenderError naming the call and the runtime's result when the loader, a runtime or a headset is missing.
    """
    def __init__(self, application: str = 'ambfplus') -> None:
        ...
    def end_frame(self, cameras: collections.abc.Sequence[Camera]) -> list:
        """
        Renders cameras[i] for eye i into the runtime's swapchain images and ends the frame (GIL released); each eye's camera, step and time (empty when wait_frame gave no eyes).
        """
    def poll_events(self) -> None:
        """
        Handles the runtime's events: begins the session when ready, ends it when stopping.
        """
    def request_exit(self) -> None:
        """
        Asks the runtime to stop the session.
        """
    def wait_frame(self) -> list:
        """
        Waits for the runtime's next frame and begins it (GIL released). Each eye to draw: pose (4x4, head-start from eye, OpenCV frame), fov (left, right, up, down angles, radians) and size (its swapchain image); empty when the runtime shows nothing now. end_frame must follow.
        """
    @property
    def ended(self) -> bool:
        """
        the runtime ended the session: no more frames
        """
    @property
    def eye_sizes(self) -> list[typing.Annotated[list[int], "FixedSize(2)"]]:
        """
        each eye's swapchain image size (width, height)
        """
    @property
    def frames(self) -> int:
        """
        frames submitted
        """
    @property
    def running(self) -> bool:
        """
        frames are expected (between ready and stopping)
        """
    @property
    def runtime(self) -> str:
        """
        the runtime's name and version
        """
    @property
    def state(self) -> str:
        """
        idle, ready, synchronized, visible, focused, stopping, loss_pending or exiting
        """
    @property
    def system(self) -> str:
        """
        the headset's name
        """
class Frame:
    """
    One capture of a camera: images, time and geometry.
    """
    def __repr__(self) -> str:
        ...
    @property
    def camera(self) -> str:
        """
        name of the camera
        """
    @property
    def depth(self) -> typing.Any:
        """
        float32 (H, W) view: metric z along the optical axis, 0 where nothing was hit
        """
    @property
    def height(self) -> int:
        ...
    @property
    def instance(self) -> typing.Any:
        """
        int32 (H, W) view: the id of the object seen (meshes and volumes), 0 where nothing was hit, or None when not rendered
        """
    @property
    def intrinsics(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 3]"]:
        """
        3x3 K; pixel (row r, column c) is centred at (c + 0.5, r + 0.5)
        """
    @property
    def label(self) -> typing.Any:
        """
        uint16 (H, W) view: the volume label id seen at each pixel, 0 elsewhere
        """
    @property
    def points(self) -> typing.Any:
        """
        float32 (H, W, 3) organised point cloud in the camera frame (OpenCV: x right, y down, z forward), (0, 0, 0) where nothing was hit: a view of the captured points pass, or without one a new array computed from depth and the intrinsics at each access; its colours and labels are rgb and label at the same pixels
        """
    @property
    def pose(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
        """
        4x4 world from camera (OpenCV camera frame) at the capture
        """
    @property
    def poses(self) -> typing.Any:
        """
        {name: 4x4 world-from-object pose} of the objects the capture was asked for (poses=True: every object), taken with the images at the same step; None when none were asked for
        """
    @property
    def rgb(self) -> typing.Any:
        """
        uint8 (H, W, 3) RGB view of the frame's colour image (row 0 at the top), or None
        """
    @property
    def segmentation(self) -> typing.Any:
        """
        uint8 (H, W, 3) view: flat RGB colours as AMBF's preprocessing shaders draw them (the camera's preprocessing shader where set), or None when not rendered
        """
    @property
    def step(self) -> int:
        """
        simulation step index of the capture
        """
    @property
    def time(self) -> float:
        """
        simulation time of the capture, seconds
        """
    @property
    def voxel(self) -> typing.Any:
        """
        int32 (H, W) view: the linear index i + nx (j + ny k) of the volume voxel whose label the pixel shows, -1 elsewhere, or None when not rendered
        """
    @property
    def width(self) -> int:
        ...
class Label:
    """
    One structure of a segmented volume (id 0 means no label).
    """
    __hash__: typing.ClassVar[None] = None
    def __eq__(self, arg0: Label) -> bool:
        ...
    def __init__(self, id: typing.SupportsInt | typing.SupportsIndex, name: str, color: typing.Annotated[collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], "FixedSize(3)"] = [255, 255, 255], removable: bool = True, critical: bool = False) -> None:
        ...
    def __repr__(self) -> str:
        ...
    @property
    def color(self) -> tuple[int, int, int]:
        ...
    @property
    def critical(self) -> bool:
        ...
    @property
    def id(self) -> int:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def removable(self) -> bool:
        ...
class VolumeData:
    """
    A segmented volume: label grid (a view, indexed [i, j, k]), label table, size, edits.
    """
    EDIT_LOG_EDITS: typing.ClassVar[int] = 4096
    EDIT_LOG_VOXELS: typing.ClassVar[int] = 262144
    def __init__(self, labels: numpy.ndarray, *, dimensions: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"] | None = None, voxel_size: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"] | None = None, label_table: typing.Any = None) -> None:
        """
        A volume from a (nx, ny, nz) uint8/uint16 label array (copied), its size in metres and its labels (a list of Label or a CSV/YAML file; named label_<id> when absent).
        """
    def __repr__(self) -> str:
        ...
    def commit(self) -> None:
        """
        makes the current labels what reset() restores
        """
    def label(self, id_or_name: typing.Any) -> Label:
        ...
    def label_counts(self) -> numpy.typing.NDArray[numpy.int64]:
        """
        voxels per label id (index = id; index 0 counts the empty voxels)
        """
    def label_ids(self, labels: typing.Any, what: str = 'labels') -> list[int]:
        """
        The ids of labels given by name or id (one, or a list), by the rule every caller uses (a name first, then a number); an unknown one raises NotFound starting with `what` and listing the table's labels.
        """
    def mark_dirty(self, lo: typing.Annotated[collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], "FixedSize(3)"] | None = None, hi: typing.Annotated[collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], "FixedSize(3)"] | None = None) -> None:
        """
        declares voxels [lo, hi) (default: all) changed through the labels view
        """
    def mark_intensity_changed(self) -> None:
        """
        declares the intensity grid changed through its view: renderers read it again
        """
    def raycast(self, origin: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], direction: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], iso: typing.SupportsFloat | typing.SupportsIndex = 0.5) -> typing.Any:
        """
        first iso-surface hit of a volume-frame ray: dict(distance, position, normal, label) or None (it brings the smoothed field up to date: while a real-time loop drills this data, call it under world.lock(), or use Volume.raycast, which takes the lock)
        """
    def remove_sphere(self, center: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], radius: typing.SupportsFloat | typing.SupportsIndex, only_removable: bool = True) -> int:
        """
        clears the voxels whose centres are within radius of center (volume frame, metres)
        """
    def reset(self) -> None:
        """
        restores the labels as loaded (or last committed)
        """
    def save_mesh(self, path: os.PathLike | str | bytes, label: typing.SupportsInt | typing.SupportsIndex = 0, iso: typing.SupportsFloat | typing.SupportsIndex = 0.5) -> int:
        """
        writes the iso-surface (of one label, or of all when 0) as .stl or .ply; returns the triangle count
        """
    def save_nrrd(self, path: os.PathLike | str | bytes, what: str = 'labels', gzip: bool = True) -> None:
        ...
    def save_slice_stack(self, folder: os.PathLike | str | bytes, prefix: str = 'plane00', format: str = 'png') -> None:
        ...
    def set_region(self, lo: typing.Annotated[collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], "FixedSize(3)"], hi: typing.Annotated[collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], "FixedSize(3)"], label: typing.SupportsInt | typing.SupportsIndex) -> int:
        """
        sets voxels [lo, hi) to label
        """
    def take_edit_log(self) -> list:
        """
        returns the edit log and starts a new one
        """
    def voxel_center(self, i: typing.SupportsInt | typing.SupportsIndex, j: typing.SupportsInt | typing.SupportsIndex, k: typing.SupportsInt | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        centre of voxel (i, j, k) in the volume frame
        """
    @property
    def dimensions(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        full extents along x, y, z, metres
        """
    @dimensions.setter
    def dimensions(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def edit_log(self) -> list:
        """
        the edits so far: dicts of revision, kind, box, changed, voxels, old_labels
        """
    @property
    def edit_log_dropped(self) -> int:
        """
        edits dropped from the log because it was full (it keeps the newest VolumeData.EDIT_LOG_EDITS edits, holding at most VolumeData.EDIT_LOG_VOXELS voxels)
        """
    @property
    def intensity(self) -> typing.Any:
        """
        (nx, ny, nz) view of the intensity (CT) grid, or None; after writing through it, call mark_intensity_changed() so renderers see the change
        """
    @property
    def label_table(self) -> list[Label]:
        ...
    @label_table.setter
    def label_table(self, arg1: collections.abc.Sequence[Label]) -> None:
        ...
    @property
    def label_type(self) -> str:
        ...
    @property
    def labels(self) -> numpy.ndarray:
        """
        (nx, ny, nz) view of the label grid, i fastest in memory; after writing through it, call mark_dirty() so renderers see the change
        """
    @property
    def patient_from_volume(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
        ...
    @property
    def revision(self) -> int:
        ...
    @property
    def shape(self) -> tuple[int, int, int]:
        ...
    @property
    def smoothed_occupancy(self) -> numpy.ndarray:
        """
        read-only (nx, ny, nz) view of the blurred occupancy (0..255) whose 0.5 level is the rendered surface, brought up to date with the edits made since whenever it is read (a view taken earlier shows it as of then until it, or raycast, is read again); while a real-time loop drills this data, read it under world.lock()
        """
    @property
    def source(self) -> str:
        ...
    @property
    def voxel_size(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
class DistanceField:
    """
    The exact signed distance (metres) from every voxel centre of a volume to a structure, clamped to a band; brought up to date by update() as the volume is edited.
    """
    def __init__(self, volume: VolumeData, labels: typing.Any, band: typing.SupportsFloat | typing.SupportsIndex = 0.005) -> None:
        """
        The field of the structure made of `labels` (names or ids, one or a list) in `volume`, clamped to `band` metres.
        """
    def at(self, i: typing.SupportsInt | typing.SupportsIndex, j: typing.SupportsInt | typing.SupportsIndex, k: typing.SupportsInt | typing.SupportsIndex) -> float:
        """
        The signed distance at voxel (i, j, k)'s centre (metres).
        """
    def sample(self, points: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        (distance, gradient) at a volume-frame point (3,), or arrays for points (N, 3): trilinear in the voxel-centre values, with that interpolant's gradient.
        """
    def update(self) -> int:
        """
        Brings the field up to the volume's edits; returns the voxels recomputed.
        """
    def values(self) -> numpy.typing.NDArray[numpy.float32]:
        """
        The signed distance of every voxel as a (nx, ny, nz) float32 array (a copy).
        """
    @property
    def band(self) -> float:
        ...
    @property
    def labels(self) -> list[int]:
        ...
    @property
    def revision(self) -> int:
        ...
    @property
    def structure_voxels(self) -> int:
        ...
class LightType:
    """
    How a light shines.
    
    Members:
    
      directional
    
      point
    
      spot
    """
    __members__: typing.ClassVar[dict[str, LightType]]
    directional: typing.ClassVar[LightType]
    point: typing.ClassVar[LightType]
    spot: typing.ClassVar[LightType]
    @typing.overload
    def __eq__(self, other: LightType) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    @typing.overload
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def __init__(self, name: str) -> None:
        """
        The member a name stands for (as files and strings write it).
        """
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: LightType) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class Simulator:
    """
    The top of the hierarchy Simulator > World > Model > Object.
    """
    @staticmethod
    def from_launch(path: os.PathLike | str | bytes, models: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex] | None = None, extra: collections.abc.Sequence[os.PathLike | str | bytes] = [], devices: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex] = [], strict: bool = False, load_world: bool = True, namespace_prefix: str = '', time_step: typing.SupportsFloat | typing.SupportsIndex = 0.001, plugins: collections.abc.Sequence[str] = [], arguments: collections.abc.Sequence[str] = []) -> Simulator:
        """
        Loads an AMBF launch file: its world file, then the model files at the launch indices `models` (AMBF's -l; None: index 1 unless `extra` is given), then `extra` files (-a), then the simulated multibodies of input `devices` (-i), then the launch file's and `plugins`' simulator plugins (--plugins). A model that fails is reported in the result's errors and leaves nothing behind, a plugin that fails is reported there too; strict=True raises instead. arguments: command-line arguments for simulator plugins (AMBF forwards those it does not know; Simulator.arguments). Returns a new simulator; see its load_report.
        """
    def __init__(self, time_step: typing.SupportsFloat | typing.SupportsIndex = 0.001, world_name: str = 'World') -> None:
        ...
    def get(self, name: str, kind: str | None = None) -> typing.Any:
        """
        world.get(name, kind)
        """
    def load_plugin(self, plugin, *args, probe: bool = False, **kwargs):
        """
        load_plugin(self: ambfplus._core.Simulator, plugin: object, name: str | None = None) -> object
        
        Loads a plugin and calls its init(): `plugin` is a C++ library (libx.so, or a name searched in AMBFPLUS_PLUGIN_PATH, the package's plugin folder and the linker's path), a Python file (x.py), an `ambfplus.plugins` entry-point name, or an ambfplus.Plugin object. Returns its PluginInfo, or None when init() declined. Raises PluginError. The plugin is attached to the simulator.
        
        
        probe=True loads a plugin file in a probe process first and raises PluginError with the probe's output when that process crashes, hangs or fails.
        """
    def step(self, n: typing.SupportsInt | typing.SupportsIndex = 1) -> None:
        """
        Advances the world by n fixed steps. StateError while a RealTimeLoop steps the world.
        """
    @property
    def arguments(self) -> list[str]:
        """
        command-line arguments for simulator plugins (set before they load)
        """
    @arguments.setter
    def arguments(self, arg1: collections.abc.Sequence[str]) -> None:
        ...
    @property
    def load_report(self) -> LoadReport:
        """
        what from_launch loaded and reported (None otherwise)
        """
    @property
    def world(self) -> World:
        ...
class World:
    """
    The scene (models and their objects) and the simulation clock.
    """
    def __contains__(self, arg0: str) -> bool:
        ...
    def __getitem__(self, arg0: str) -> typing.Any:
        ...
    def __init__(self, time_step: typing.SupportsFloat | typing.SupportsIndex = 0.001, name: str = 'World') -> None:
        """
        Creates a simulator with an empty world and returns the world.
        """
    def __len__(self) -> int:
        ...
    def __repr__(self) -> str:
        ...
    def add_actuator(self, name: str, parent: RigidBody, **kwargs) -> ConstraintActuator:
        """
        Adds a constraint actuator on parent that holds bodies on request (hold 'fixed': the body keeps its pose relative to the actuator; 'point': only the point is held). Keywords:
          hold (ActuatorHold | str): fixed (the body keeps its pose) or point
          max_impulse (float): N s per step (point hold)
          tau (float): share of the point error corrected per step (point hold)
          location (numpy.ndarray): 4x4 frame in the parent's frame
          pose (numpy.ndarray): 4x4 frame in the world, now
          visible (bool)
          visible_size (float): m
        """
    def add_body(self, name: str, shape: ShapeKind | str | None = None, *, size: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"] | None = None, radius: typing.SupportsFloat | typing.SupportsIndex | None = None, height: typing.SupportsFloat | typing.SupportsIndex | None = None, mesh: os.PathLike | str | bytes | None = None, scale: typing.SupportsFloat | typing.SupportsIndex = 1.0, pose: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"] | None = None, mass: typing.SupportsFloat | typing.SupportsIndex = 1.0, color: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex] | None = None, specular: typing.SupportsFloat | typing.SupportsIndex | None = None, shininess: typing.SupportsFloat | typing.SupportsIndex | None = None, **kwargs) -> RigidBody:
        """
        Adds a rigid body: shape is box (size = full extents), sphere (radius), cylinder, capsule or cone (radius, height along axis, z unless axis='x' or 'y'; a capsule's height includes its caps), plane (z = 0, infinite) or mesh (mesh = file, scale; the default when mesh is given); pose is a 4x4 world-from-body matrix. Physics (mass > 0 moves under gravity; 0 is static): inertia, inertial_offset (4x4), friction, rolling_friction, restitution, linear_damping, angular_damping, kinematic, gravity ((x, y, z) m/s^2: its own instead of the world's), collision (False: none), collision_mesh, collision_type (concave, convex_mesh, convex_hull, point_cloud), collision_shapes ([{shape, size/radius/height/axis, pose}]), margin, groups ([0..31]), axis.
        """
    def add_camera(self, name: str, width: typing.SupportsInt | typing.SupportsIndex = 640, height: typing.SupportsInt | typing.SupportsIndex = 480, fov_y: typing.SupportsFloat | typing.SupportsIndex = 0.7, near: typing.SupportsFloat | typing.SupportsIndex = 0.1, far: typing.SupportsFloat | typing.SupportsIndex = 10.0, *, pose: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"] | None = None, background: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex] = [0.0, 0.0, 0.0], shadows: bool = False, antialiasing: typing.SupportsInt | typing.SupportsIndex = 1, looks: bool = False) -> Camera:
        """
        Adds a pinhole camera (OpenCV frame: x right, y down, z forward); fov_y is the vertical field of view in radians, near and far the clipping distances in metres. shadows, antialiasing (1 = off to 4, see Camera.antialiasing) and looks (volumes' ambient occlusion, bone texture and wet highlights) change the rgb pass only.
        """
    def add_drill(self, name: str, volume: Volume, **kwargs) -> Drill:
        """
        Adds a drill working on `volume`. Keywords:
          burr_diameters (list[float]): m
          burr (int): index into burr_diameters
          cursors (int): tip + shaft cursors, 1..16
          spacing (float): m between cursors along the shaft
          shaft_radii (list[float]): m, one per shaft cursor
          stiffness (float): N/m
          damping (float): N s/m
          max_force (float): N
          soft_start (float): s over which forces ramp up
          static_friction (float)
          dynamic_friction (float)
          friction (dict[str, float]): {static, dynamic}
          removal (RemovalMode | str): physical or compatible
          cutting_rate (float): m^3 / (s N) at full speed
          voxels_per_step (list[int]): per burr (compatible removal)
          pose (numpy.ndarray): 4x4 initial goal, world from drill
          fixtures (list[dict]): forbidden regions: {structure, start, max_force, stop, enabled} each
        """
    def add_ghost(self, name: str, shape: ShapeKind | str | None = None, *, size: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"] | None = None, radius: typing.SupportsFloat | typing.SupportsIndex | None = None, height: typing.SupportsFloat | typing.SupportsIndex | None = None, mesh: os.PathLike | str | bytes | None = None, scale: typing.SupportsFloat | typing.SupportsIndex = 1.0, pose: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"] | None = None, color: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex] | None = None, visible: bool = True, **kwargs) -> RigidBody:
        """
        Adds a ghost object (AMBF's ghost objects): a shape as add_body takes it that touches nothing (no force, rays pass through) and reports, after every step, the bodies overlapping it (body.overlapping, Bullet's narrow phase). It moves by its pose or rides on a parent (attach_to). Collision keywords of add_body (collision_mesh, collision_type, collision_shapes, margin) shape what it tests.
        """
    def add_input_device(self, name: str, device: Device, drill: Drill, **kwargs) -> InputDevice:
        """
        Binds a device to a drill, as a surgeon holds it. Keywords:
          workspace_scale (float): world m per device m
          reference (Object | None): the object whose axes device motion follows
          drill_button (int): held: the burr spins (-1: none)
          clutch_button (int): held: the device moves alone (-1: none)
          burr_button (int): pressed: the next burr (-1: none)
          max_force (float): N sent at most
          force_scale (float): force sent per newton of the drill's
        """
    def add_joint(self, name: str, parent: RigidBody, child: RigidBody, type: JointType | str = 'revolute', **kwargs) -> Joint:
        """
        Adds a joint between two bodies (type: revolute/hinge/continuous, prismatic/slider, fixed, spring, torsion spring, p2p, cone twist, six dof, six dof spring); pivots and axes are in each body's frame. Keywords:
          type (JointType | str): revolute, prismatic, fixed, spring, ...
          parent_pivot (tuple[float, float, float]): in the parent's frame, m
          parent_axis (tuple[float, float, float]): in the parent's frame
          child_pivot (tuple[float, float, float]): in the child's frame, m
          child_axis (tuple[float, float, float]): in the child's frame
          offset (float): the parent frame's turn about the axis, rad
          child_offset (float): the child frame's turn about the axis, rad
          lower (float | None): limit, rad or m
          upper (float | None): limit, rad or m
          damping (float): N m s/rad or N s/m
          stiffness (float): springs: N m/rad or N/m
          equilibrium (float): springs: rest position
          max_motor_impulse (float): N m s (or N s) per step
          erp (float)
          cfm (float)
          controller (dict[str, Any] | None): {p, i, d, output}
          passive (bool): left out of its root body's joints, not controlled
          ignore_inter_collision (bool): parent and child do not collide
        """
    def add_light(self, name: str, type: LightType | str = 'directional', *, position: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"] = ..., direction: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"] = ..., color: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex] = [1.0, 1.0, 1.0], intensity: typing.SupportsFloat | typing.SupportsIndex = 1.0, spot_cutoff: typing.SupportsFloat | typing.SupportsIndex = 0.7, spot_exponent: typing.SupportsFloat | typing.SupportsIndex = 0.7, attenuation: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"] = ..., shadow_quality: typing.SupportsInt | typing.SupportsIndex = 3) -> Light:
        """
        Adds a directional, point or spot light shining along direction. A world without lights is lit by a headlight at each camera. shadow_quality: 0 casts no shadow, 1..5 shadow maps of 256 to 4096 texels a side (drawn by cameras with shadows on).
        """
    def add_model(self, name: str) -> Model:
        """
        Adds an empty model (a group of objects).
        """
    def add_sensor(self, name: str, parent: RigidBody, **kwargs) -> ProximitySensor:
        """
        Adds a proximity sensor fixed to parent, updated after every physics step; a ray reaches offset + direction * range (sensor frame, default +x from the origin). Keywords:
          range (float): m each ray reaches (per unit of its direction)
          offset (tuple[float, float, float]): the one ray's start, sensor frame
          direction (tuple[float, float, float]): the one ray's direction, sensor frame
          rays (list[Any]): [{offset, direction}] or [(offset, direction)]
          parametric (dict[str, float]): {resolution, horizontal angle, vertical angle, start offset}
          location (numpy.ndarray): 4x4 frame in the parent's frame
          pose (numpy.ndarray): 4x4 frame in the world, now
          visible (bool)
          visible_size (float): m
        """
    def add_soft_body(self, name: str, mesh: os.PathLike | str | bytes, **kwargs) -> SoftBody:
        """
        Adds a soft body made from a mesh file (STL, OBJ, ...): nodes at its distinct vertices, links along its triangle edges. Keywords:
          scale (float): of the mesh's vertices
          pose (numpy.ndarray): 4x4 world from the mesh frame
          mass (float): kg, shared evenly by the nodes
          margin (float): collision margin, m
          config (dict[str, Any] | None): AMBF's config block (kLST, ... fixed nodes)
          fixed_nodes (list[int]): nodes pinned where they are
          randomize_constraints (bool): shuffle the order the solver takes the links in
          color (tuple[float, ...]): RGB or RGBA in 0..1
          specular (float): Phong factor
          shininess (float): Phong exponent
          visible (bool): drawn in images (False: it still collides)
        """
    def add_volume(self, name: str, data: VolumeData, *, pose: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"] | None = None, iso: typing.SupportsFloat | typing.SupportsIndex = 0.5, quality: typing.SupportsFloat | typing.SupportsIndex = 0.5, optical_density: typing.SupportsFloat | typing.SupportsIndex = 1.0, specular: typing.SupportsFloat | typing.SupportsIndex | None = None, shininess: typing.SupportsFloat | typing.SupportsIndex | None = None) -> Volume:
        """
        Places volume data in the world; pose is world from the volume frame (centred on the grid). Several volumes may share one VolumeData. specular (0..1) and shininess (Phong exponent) set the surface's material (defaults 0.15 and 24).
        """
    def close_plugins(self) -> None:
        """
        Calls close() on every plugin (reverse call order) and lets them go; the world does it when it is destroyed.
        """
    def get(self, name: str, kind: str | None = None) -> typing.Any:
        """
        The object a name refers to: the exact name, else AMBF's lookup (qualified name '/ambf/env/l1', identifier 'BODY l1', or a unique part of either; a part that also matches joints means the one other object). KeyError (ambfplus.NotFound) when none or several match; kind ('body', 'joint', ...) narrows the search.
        """
    def keyboard(self, key: typing.SupportsInt | typing.SupportsIndex, scancode: typing.SupportsInt | typing.SupportsIndex, action: typing.SupportsInt | typing.SupportsIndex, mods: typing.SupportsInt | typing.SupportsIndex) -> None:
        """
        Gives the plugins a key event (GLFW codes).
        """
    def load_adf(self, path: os.PathLike | str | bytes) -> Model:
        """
        Loads an AMBF model file as a new model (all or nothing) and returns it.
        """
    def load_launch(self, path: os.PathLike | str | bytes, models: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex] | None = None, extra: collections.abc.Sequence[os.PathLike | str | bytes] = [], devices: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex] = [], strict: bool = False, load_world: bool = True, namespace_prefix: str = '', plugins: collections.abc.Sequence[str] = []) -> LoadReport:
        """
        Loads an AMBF launch file: its world file, then the model files at the launch indices `models` (AMBF's -l; None: index 1 unless `extra` is given), then `extra` files (-a), then the simulated multibodies of input `devices` (-i), then the launch file's and `plugins`' simulator plugins (--plugins). A model that fails is reported in the result's errors and leaves nothing behind, a plugin that fails is reported there too; strict=True raises instead.
        """
    def load_plugin(self, plugin, *args, probe: bool = False, **kwargs):
        """
        load_plugin(self: ambfplus._core.World, plugin: object, scope_object: object = None, name: str | None = None) -> object
        
        Loads a plugin and calls its init(): `plugin` is a C++ library (libx.so, or a name searched in AMBFPLUS_PLUGIN_PATH, the package's plugin folder and the linker's path), a Python file (x.py), an `ambfplus.plugins` entry-point name, or an ambfplus.Plugin object. Returns its PluginInfo, or None when init() declined. Raises PluginError. scope_object: None (this world), the simulator, a model or an object.
        
        
        probe=True loads a plugin file in a probe process first and raises PluginError with the probe's output when that process crashes, hangs or fails.
        """
    def load_volumes(self, path: os.PathLike | str | bytes, labels: os.PathLike | str | bytes | None = None) -> list:
        """
        Loads the volumes: of an AMBF model file (its bodies and joints come with ADF loading) into a new model, then the drills: it declares on them (ambfplus extension); labels (CSV/YAML) overrides their label tables. Returns the volumes.
        """
    def load_world_file(self, path: os.PathLike | str | bytes) -> None:
        """
        Loads an AMBF world file: gravity, namespace, environment, lights and cameras.
        """
    def lock(self) -> typing.Any:
        """
        A context manager holding the world's state lock: a real-time loop's steps and captures from other threads wait meanwhile. Python may run other threads while it is held (the GIL changes hands), so hold it for a few lines at most; to read state for another thread, use read_state.
        """
    def lookup(self, query: str, kind: str | None = None) -> list:
        """
        Every object the query refers to (exact matches, else substring matches).
        """
    def mouse_button(self, button: typing.SupportsInt | typing.SupportsIndex, action: typing.SupportsInt | typing.SupportsIndex, mods: typing.SupportsInt | typing.SupportsIndex) -> None:
        """
        Gives the plugins a mouse button event (GLFW codes).
        """
    def mouse_move(self, x: typing.SupportsFloat | typing.SupportsIndex, y: typing.SupportsFloat | typing.SupportsIndex) -> None:
        """
        Gives the plugins the mouse's position (pixels).
        """
    def mouse_scroll(self, dx: typing.SupportsFloat | typing.SupportsIndex, dy: typing.SupportsFloat | typing.SupportsIndex) -> None:
        """
        Gives the plugins a scroll event.
        """
    def read_state(self, objects: collections.abc.Sequence[Object]) -> dict:
        """
        One consistent read of several objects, in one call that holds the world's lock with the GIL released (nothing else of Python runs under it, so a real-time loop never waits for Python). Returns {'time': s, 'objects': [one dict per object, in order]}; each has 'pose' (4x4), a camera's 'intrinsics' (3x3), a drill's 'force' (N, world frame) and 'critical_distances' ({structure: metres}).
        """
    def reset_plugins(self) -> None:
        """
        Calls every plugin's reset() (the scene itself is not reset).
        """
    def send_key(self, key: typing.SupportsInt | typing.SupportsIndex, scancode: typing.SupportsInt | typing.SupportsIndex = 0, action: typing.SupportsInt | typing.SupportsIndex = 1, mods: typing.SupportsInt | typing.SupportsIndex = 0) -> None:
        """
        Gives the plugins a key event (GLFW's codes; action 0 release, 1 press, 2 repeat).
        """
    def start_step_log(self, objects: collections.abc.Sequence[Object]) -> None:
        """
        Logs every step's state of these objects from now on (poses; drills: goal, force, on, burr; input devices: readings and force); take_step_log() drains it.
        """
    def step(self, n: typing.SupportsInt | typing.SupportsIndex = 1) -> None:
        """
        Advances the clock by n fixed steps. StateError while a RealTimeLoop steps the world.
        """
    def stop_step_log(self) -> None:
        """
        Stops logging steps (rows not taken are dropped).
        """
    def take_step_log(self) -> dict:
        """
        The steps logged since the last call: {'step', 'time', '<object>.<field>': ...}.
        """
    @property
    def bodies(self) -> list:
        ...
    @property
    def cameras(self) -> list:
        ...
    @property
    def default_model(self) -> Model:
        ...
    @property
    def drills(self) -> list:
        ...
    @property
    def gravity(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        m/s^2, world frame
        """
    @gravity.setter
    def gravity(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def input_devices(self) -> list:
        ...
    @property
    def joints(self) -> list:
        ...
    @property
    def lights(self) -> list:
        ...
    @property
    def models(self) -> list:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def namespace(self) -> str:
        """
        namespace of models whose files name none
        """
    @namespace.setter
    def namespace(self, arg1: str) -> None:
        ...
    @property
    def objects(self) -> list:
        ...
    @property
    def plugins(self) -> list:
        """
        The attached plugins in call order: simulator, world, model, then object scope, each in the order attached.
        """
    @property
    def shader(self) -> typing.Any:
        """
        the shader of bodies whose model and own material name none (AMBF's world `shaders`): None (the engine's own), 'builtin', or (vertex_path, fragment_path)
        """
    @shader.setter
    def shader(self, arg1: typing.Any) -> None:
        ...
    @property
    def simulator(self) -> Simulator:
        ...
    @property
    def step_index(self) -> int:
        """
        fixed steps taken so far
        """
    @property
    def time(self) -> float:
        """
        simulation time, seconds
        """
    @property
    def time_step(self) -> float:
        """
        seconds per fixed step
        """
    @property
    def volumes(self) -> list:
        ...
class Model:
    """
    A group of objects; names are unique across the whole world.
    """
    def __repr__(self) -> str:
        ...
    def add_actuator(self, name: str, parent: RigidBody, **kwargs) -> ConstraintActuator:
        """
        Adds a constraint actuator on parent that holds bodies on request (hold 'fixed': the body keeps its pose relative to the actuator; 'point': only the point is held). Keywords:
          hold (ActuatorHold | str): fixed (the body keeps its pose) or point
          max_impulse (float): N s per step (point hold)
          tau (float): share of the point error corrected per step (point hold)
          location (numpy.ndarray): 4x4 frame in the parent's frame
          pose (numpy.ndarray): 4x4 frame in the world, now
          visible (bool)
          visible_size (float): m
        """
    def add_body(self, name: str, shape: ShapeKind | str | None = None, *, size: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"] | None = None, radius: typing.SupportsFloat | typing.SupportsIndex | None = None, height: typing.SupportsFloat | typing.SupportsIndex | None = None, mesh: os.PathLike | str | bytes | None = None, scale: typing.SupportsFloat | typing.SupportsIndex = 1.0, pose: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"] | None = None, mass: typing.SupportsFloat | typing.SupportsIndex = 1.0, color: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex] | None = None, specular: typing.SupportsFloat | typing.SupportsIndex | None = None, shininess: typing.SupportsFloat | typing.SupportsIndex | None = None, **kwargs) -> RigidBody:
        """
        Adds a rigid body: shape is box (size = full extents), sphere (radius), cylinder, capsule or cone (radius, height along axis, z unless axis='x' or 'y'; a capsule's height includes its caps), plane (z = 0, infinite) or mesh (mesh = file, scale; the default when mesh is given); pose is a 4x4 world-from-body matrix. Physics (mass > 0 moves under gravity; 0 is static): inertia, inertial_offset (4x4), friction, rolling_friction, restitution, linear_damping, angular_damping, kinematic, gravity ((x, y, z) m/s^2: its own instead of the world's), collision (False: none), collision_mesh, collision_type (concave, convex_mesh, convex_hull, point_cloud), collision_shapes ([{shape, size/radius/height/axis, pose}]), margin, groups ([0..31]), axis.
        """
    def add_camera(self, name: str, width: typing.SupportsInt | typing.SupportsIndex = 640, height: typing.SupportsInt | typing.SupportsIndex = 480, fov_y: typing.SupportsFloat | typing.SupportsIndex = 0.7, near: typing.SupportsFloat | typing.SupportsIndex = 0.1, far: typing.SupportsFloat | typing.SupportsIndex = 10.0, *, pose: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"] | None = None, background: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex] = [0.0, 0.0, 0.0], shadows: bool = False, antialiasing: typing.SupportsInt | typing.SupportsIndex = 1, looks: bool = False) -> Camera:
        """
        Adds a pinhole camera (OpenCV frame: x right, y down, z forward); fov_y is the vertical field of view in radians, near and far the clipping distances in metres. shadows, antialiasing (1 = off to 4, see Camera.antialiasing) and looks (volumes' ambient occlusion, bone texture and wet highlights) change the rgb pass only.
        """
    def add_drill(self, name: str, volume: Volume, **kwargs) -> Drill:
        """
        Adds a drill working on `volume`. Keywords:
          burr_diameters (list[float]): m
          burr (int): index into burr_diameters
          cursors (int): tip + shaft cursors, 1..16
          spacing (float): m between cursors along the shaft
          shaft_radii (list[float]): m, one per shaft cursor
          stiffness (float): N/m
          damping (float): N s/m
          max_force (float): N
          soft_start (float): s over which forces ramp up
          static_friction (float)
          dynamic_friction (float)
          friction (dict[str, float]): {static, dynamic}
          removal (RemovalMode | str): physical or compatible
          cutting_rate (float): m^3 / (s N) at full speed
          voxels_per_step (list[int]): per burr (compatible removal)
          pose (numpy.ndarray): 4x4 initial goal, world from drill
          fixtures (list[dict]): forbidden regions: {structure, start, max_force, stop, enabled} each
        """
    def add_ghost(self, name: str, shape: ShapeKind | str | None = None, *, size: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"] | None = None, radius: typing.SupportsFloat | typing.SupportsIndex | None = None, height: typing.SupportsFloat | typing.SupportsIndex | None = None, mesh: os.PathLike | str | bytes | None = None, scale: typing.SupportsFloat | typing.SupportsIndex = 1.0, pose: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"] | None = None, color: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex] | None = None, visible: bool = True, **kwargs) -> RigidBody:
        """
        Adds a ghost object (AMBF's ghost objects): a shape as add_body takes it that touches nothing (no force, rays pass through) and reports, after every step, the bodies overlapping it (body.overlapping, Bullet's narrow phase). It moves by its pose or rides on a parent (attach_to). Collision keywords of add_body (collision_mesh, collision_type, collision_shapes, margin) shape what it tests.
        """
    def add_input_device(self, name: str, device: Device, drill: Drill, **kwargs) -> InputDevice:
        """
        Binds a device to a drill, as a surgeon holds it. Keywords:
          workspace_scale (float): world m per device m
          reference (Object | None): the object whose axes device motion follows
          drill_button (int): held: the burr spins (-1: none)
          clutch_button (int): held: the device moves alone (-1: none)
          burr_button (int): pressed: the next burr (-1: none)
          max_force (float): N sent at most
          force_scale (float): force sent per newton of the drill's
        """
    def add_joint(self, name: str, parent: RigidBody, child: RigidBody, type: JointType | str = 'revolute', **kwargs) -> Joint:
        """
        Adds a joint between two bodies (type: revolute/hinge/continuous, prismatic/slider, fixed, spring, torsion spring, p2p, cone twist, six dof, six dof spring); pivots and axes are in each body's frame. Keywords:
          type (JointType | str): revolute, prismatic, fixed, spring, ...
          parent_pivot (tuple[float, float, float]): in the parent's frame, m
          parent_axis (tuple[float, float, float]): in the parent's frame
          child_pivot (tuple[float, float, float]): in the child's frame, m
          child_axis (tuple[float, float, float]): in the child's frame
          offset (float): the parent frame's turn about the axis, rad
          child_offset (float): the child frame's turn about the axis, rad
          lower (float | None): limit, rad or m
          upper (float | None): limit, rad or m
          damping (float): N m s/rad or N s/m
          stiffness (float): springs: N m/rad or N/m
          equilibrium (float): springs: rest position
          max_motor_impulse (float): N m s (or N s) per step
          erp (float)
          cfm (float)
          controller (dict[str, Any] | None): {p, i, d, output}
          passive (bool): left out of its root body's joints, not controlled
          ignore_inter_collision (bool): parent and child do not collide
        """
    def add_light(self, name: str, type: LightType | str = 'directional', *, position: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"] = ..., direction: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"] = ..., color: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex] = [1.0, 1.0, 1.0], intensity: typing.SupportsFloat | typing.SupportsIndex = 1.0, spot_cutoff: typing.SupportsFloat | typing.SupportsIndex = 0.7, spot_exponent: typing.SupportsFloat | typing.SupportsIndex = 0.7, attenuation: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"] = ..., shadow_quality: typing.SupportsInt | typing.SupportsIndex = 3) -> Light:
        """
        Adds a directional, point or spot light shining along direction. A world without lights is lit by a headlight at each camera. shadow_quality: 0 casts no shadow, 1..5 shadow maps of 256 to 4096 texels a side (drawn by cameras with shadows on).
        """
    def add_sensor(self, name: str, parent: RigidBody, **kwargs) -> ProximitySensor:
        """
        Adds a proximity sensor fixed to parent, updated after every physics step; a ray reaches offset + direction * range (sensor frame, default +x from the origin). Keywords:
          range (float): m each ray reaches (per unit of its direction)
          offset (tuple[float, float, float]): the one ray's start, sensor frame
          direction (tuple[float, float, float]): the one ray's direction, sensor frame
          rays (list[Any]): [{offset, direction}] or [(offset, direction)]
          parametric (dict[str, float]): {resolution, horizontal angle, vertical angle, start offset}
          location (numpy.ndarray): 4x4 frame in the parent's frame
          pose (numpy.ndarray): 4x4 frame in the world, now
          visible (bool)
          visible_size (float): m
        """
    def add_soft_body(self, name: str, mesh: os.PathLike | str | bytes, **kwargs) -> SoftBody:
        """
        Adds a soft body made from a mesh file (STL, OBJ, ...): nodes at its distinct vertices, links along its triangle edges. Keywords:
          scale (float): of the mesh's vertices
          pose (numpy.ndarray): 4x4 world from the mesh frame
          mass (float): kg, shared evenly by the nodes
          margin (float): collision margin, m
          config (dict[str, Any] | None): AMBF's config block (kLST, ... fixed nodes)
          fixed_nodes (list[int]): nodes pinned where they are
          randomize_constraints (bool): shuffle the order the solver takes the links in
          color (tuple[float, ...]): RGB or RGBA in 0..1
          specular (float): Phong factor
          shininess (float): Phong exponent
          visible (bool): drawn in images (False: it still collides)
        """
    def add_volume(self, name: str, data: VolumeData, *, pose: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"] | None = None, iso: typing.SupportsFloat | typing.SupportsIndex = 0.5, quality: typing.SupportsFloat | typing.SupportsIndex = 0.5, optical_density: typing.SupportsFloat | typing.SupportsIndex = 1.0, specular: typing.SupportsFloat | typing.SupportsIndex | None = None, shininess: typing.SupportsFloat | typing.SupportsIndex | None = None) -> Volume:
        """
        Places volume data in the world; pose is world from the volume frame (centred on the grid). Several volumes may share one VolumeData. specular (0..1) and shininess (Phong exponent) set the surface's material (defaults 0.15 and 24).
        """
    @property
    def name(self) -> str:
        ...
    @property
    def objects(self) -> list:
        ...
    @property
    def shader(self) -> typing.Any:
        """
        the shader of its bodies that name none (AMBF's model `shaders`): None (the world's), 'builtin' (the engine's own), or (vertex_path, fragment_path)
        """
    @shader.setter
    def shader(self, arg1: typing.Any) -> None:
        ...
    @property
    def world(self) -> World:
        ...
class Object:
    """
    Anything in a world with a unique name.
    """
    def __repr__(self) -> str:
        ...
    def attach_to(self, parent: Object, local: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"] | None = None) -> None:
        """
        Rides on parent after every step at `local` (4x4 parent-from-object; default: where it is now). None detaches.
        """
    @property
    def attached_to(self) -> typing.Any:
        ...
    @property
    def id(self) -> int:
        """
        stable instance id (>= 1) used by segmentation
        """
    @property
    def identifier(self) -> str:
        """
        the ADF block it was loaded from ('BODY l1'), or ''
        """
    @property
    def key(self) -> str:
        """
        its name unique in the world, as AMBF's client keys it: the namespace below /ambf/env/ and the name ('psm1/baselink'), the bare name in the root namespace; legends and recordings use it
        """
    @property
    def kind(self) -> str:
        ...
    @property
    def model(self) -> Model:
        ...
    @property
    def name(self) -> str:
        """
        the name it was declared with; two namespaces may each have one
        """
    @property
    def namespace(self) -> str:
        """
        AMBF namespace, e.g. '/ambf/env/' (setting it changes the key; a key taken is an ArgumentError)
        """
    @namespace.setter
    def namespace(self, arg1: str) -> None:
        ...
    @property
    def pose(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
        """
        4x4 world-from-object rigid transform (a copy; assign to change it)
        """
    @pose.setter
    def pose(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"]) -> None:
        ...
    @property
    def qualified_name(self) -> str:
        """
        namespace + name
        """
class Camera(Object):
    """
    A pinhole camera; pose is world from camera in the OpenCV frame.
    """
    def capture(self, out: typing.Any = None, passes: typing.Any = None, poses: typing.Any = None) -> typing.Any:
        """
        Renders (GIL released) and returns a Frame of NumPy views. passes: the images to render (names from capture_passes(); default camera.passes), and only those. out=Frame refills that frame's images in place; out={'rgb': a, 'depth': b, ...} renders into preallocated arrays. poses: object names (or True for all) whose world poses the frame records in frame.poses, taken with the images.
        """
    def look_at(self, eye: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], target: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], up: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"] = ...) -> None:
        """
        Places the camera at eye looking at target, with image up along up.
        """
    @property
    def antialiasing(self) -> int:
        """
        the rgb pass's antialiasing at edges and contrasts: 1 is off, 2 blends a pixel's centre (1/2) with its four corners (1/8 each), 3 and 4 average a k x k grid of samples; ground-truth passes stay one exact sample per pixel centre
        """
    @antialiasing.setter
    def antialiasing(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def far(self) -> float:
        ...
    @property
    def fov_y(self) -> float:
        """
        vertical field of view, radians (the principal point stays)
        """
    @fov_y.setter
    def fov_y(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def height(self) -> int:
        ...
    @property
    def intrinsics(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 3]"]:
        """
        3x3 K: fx = fy = H / (2 tan(fov_y / 2)), cx = W / 2, cy = H / 2; pixel (row r, column c) is centred at (c + 0.5, r + 0.5)
        """
    @property
    def looks(self) -> bool:
        """
        whether the rgb pass gives volumes ambient occlusion from their occupancy, a world-fixed bone texture (the CT intensity where the volume has one) and wet specular highlights; ground-truth passes never change
        """
    @looks.setter
    def looks(self, arg1: bool) -> None:
        ...
    @property
    def near(self) -> float:
        ...
    @property
    def passes(self) -> list:
        """
        what a capture renders unless told otherwise
        """
    @passes.setter
    def passes(self, arg1: typing.Any) -> None:
        ...
    @property
    def preprocessing_shader(self) -> typing.Any:
        """
        AMBF's `preprocessing shaders`: what the segmentation pass draws meshes with (volumes keep their label colours); None or 'builtin': the engine's equivalent of AMBF's
        """
    @preprocessing_shader.setter
    def preprocessing_shader(self, arg1: typing.Any) -> None:
        ...
    @property
    def principal_point(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 1]"]:
        """
        (cx, cy) in pixels; (W/2, H/2) unless moved (an off-axis camera)
        """
    @principal_point.setter
    def principal_point(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"]) -> None:
        ...
    @property
    def projection(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
        """
        4x4 OpenGL clip-from-camera matrix used to render
        """
    @property
    def publish(self) -> dict:
        """
        what an ADF asked it to publish: image/depth flags and intervals (every n-th render), depth noise (mean, std_dev, bias) or None
        """
    @property
    def shadows(self) -> bool:
        """
        whether the rgb pass draws the shadows of lights with a shadow_quality above 0 (directional and spot); ground-truth passes never change
        """
    @shadows.setter
    def shadows(self, arg1: bool) -> None:
        ...
    @property
    def width(self) -> int:
        ...
class Light(Object):
    """
    A directional, point or spot light shining along its +z axis.
    """
    @property
    def color(self) -> typing.Annotated[list[float], "FixedSize(3)"]:
        ...
    @property
    def direction(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def intensity(self) -> float:
        ...
    @property
    def shadow_quality(self) -> int:
        """
        AMBF's `shadow quality`: 0 casts no shadow, 1..5 shadow maps of 256 to 4096 texels a side (directional and spot lights)
        """
    @shadow_quality.setter
    def shadow_quality(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def type(self) -> str:
        ...
class Volume(Object):
    """
    Segmented volume data placed in a world, rendered by ray casting.
    """
    def mark_dirty(self, lo: typing.Annotated[collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], "FixedSize(3)"] | None = None, hi: typing.Annotated[collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], "FixedSize(3)"] | None = None) -> None:
        """
        declares voxels [lo, hi) (default: all) changed through the labels view
        """
    def raycast(self, origin: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], direction: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> typing.Any:
        """
        first iso-surface hit of a world-frame ray: dict(distance, position, normal, label) or None (under the world's lock: a real-time loop waits for it)
        """
    def remove_sphere(self, center: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], radius: typing.SupportsFloat | typing.SupportsIndex, only_removable: bool = True) -> int:
        """
        clears voxels within radius of a world-frame centre; returns how many
        """
    def reset(self) -> None:
        """
        restores the data's labels as loaded (or last committed)
        """
    def voxel_to_world(self, ijk: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        the world point of fractional voxel indices
        """
    def world_to_voxel(self, point: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        fractional voxel indices (centres at integers) of a world point
        """
    @property
    def data(self) -> VolumeData:
        ...
    @property
    def empty_space_skipping(self) -> bool:
        """
        rays skip empty bricks (off: every half voxel, the naive baseline)
        """
    @empty_space_skipping.setter
    def empty_space_skipping(self, arg1: bool) -> None:
        ...
    @property
    def iso(self) -> float:
        """
        iso level of the smoothed occupancy
        """
    @iso.setter
    def iso(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def labels(self) -> typing.Any:
        """
        the data's label grid view (see VolumeData.labels)
        """
    @property
    def last_upload(self) -> dict:
        """
        what the last render sent to the GPU: rendered, full, voxels, seconds
        """
    @property
    def optical_density(self) -> float:
        ...
    @property
    def quality(self) -> float:
        ...
    @property
    def shininess(self) -> float:
        """
        Phong exponent
        """
    @property
    def specular(self) -> float:
        """
        Phong specular factor, 0..1
        """
    @property
    def world_from_voxel(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
        """
        4x4: voxel (i, j, k)'s centre is this times (i, j, k, 1)
        """
class ShapeKind:
    """
    A rigid body's geometry.
    
    Members:
    
      box
    
      sphere
    
      cylinder
    
      capsule
    
      cone
    
      plane
    
      mesh
    
      none
    """
    __members__: typing.ClassVar[dict[str, ShapeKind]]
    box: typing.ClassVar[ShapeKind]
    capsule: typing.ClassVar[ShapeKind]
    cone: typing.ClassVar[ShapeKind]
    cylinder: typing.ClassVar[ShapeKind]
    mesh: typing.ClassVar[ShapeKind]
    none: typing.ClassVar[ShapeKind]
    plane: typing.ClassVar[ShapeKind]
    sphere: typing.ClassVar[ShapeKind]
    @typing.overload
    def __eq__(self, other: ShapeKind) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    @typing.overload
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def __init__(self, name: str) -> None:
        """
        The member a name stands for (as files and strings write it).
        """
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: ShapeKind) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class Axis:
    """
    A body axis (cylinders, capsules and cones run along one).
    
    Members:
    
      x
    
      y
    
      z
    """
    __members__: typing.ClassVar[dict[str, Axis]]
    x: typing.ClassVar[Axis]
    y: typing.ClassVar[Axis]
    z: typing.ClassVar[Axis]
    @typing.overload
    def __eq__(self, other: Axis) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    @typing.overload
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def __init__(self, name: str) -> None:
        """
        The member a name stands for (as files and strings write it).
        """
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: Axis) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class MeshCollision:
    """
    How a body's collision shape is made from a mesh.
    
    Members:
    
      concave
    
      convex_mesh
    
      convex_hull
    
      point_cloud
    """
    __members__: typing.ClassVar[dict[str, MeshCollision]]
    concave: typing.ClassVar[MeshCollision]
    convex_hull: typing.ClassVar[MeshCollision]
    convex_mesh: typing.ClassVar[MeshCollision]
    point_cloud: typing.ClassVar[MeshCollision]
    @typing.overload
    def __eq__(self, other: MeshCollision) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    @typing.overload
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def __init__(self, name: str) -> None:
        """
        The member a name stands for (as files and strings write it).
        """
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: MeshCollision) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class JointType:
    """
    How a joint lets its child move.
    
    Members:
    
      revolute
    
      prismatic
    
      fixed
    
      linear_spring
    
      torsion_spring
    
      p2p
    
      cone_twist
    
      six_dof
    
      six_dof_spring
    """
    __members__: typing.ClassVar[dict[str, JointType]]
    cone_twist: typing.ClassVar[JointType]
    fixed: typing.ClassVar[JointType]
    linear_spring: typing.ClassVar[JointType]
    p2p: typing.ClassVar[JointType]
    prismatic: typing.ClassVar[JointType]
    revolute: typing.ClassVar[JointType]
    six_dof: typing.ClassVar[JointType]
    six_dof_spring: typing.ClassVar[JointType]
    torsion_spring: typing.ClassVar[JointType]
    @typing.overload
    def __eq__(self, other: JointType) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    @typing.overload
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def __init__(self, name: str) -> None:
        """
        The member a name stands for (as files and strings write it).
        """
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: JointType) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class ControlOutput:
    """
    What a joint controller drives.
    
    Members:
    
      effort
    
      velocity
    """
    __members__: typing.ClassVar[dict[str, ControlOutput]]
    effort: typing.ClassVar[ControlOutput]
    velocity: typing.ClassVar[ControlOutput]
    @typing.overload
    def __eq__(self, other: ControlOutput) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    @typing.overload
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def __init__(self, name: str) -> None:
        """
        The member a name stands for (as files and strings write it).
        """
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: ControlOutput) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class ActuatorHold:
    """
    How a constraint actuator holds a body.
    
    Members:
    
      fixed
    
      point
    """
    __members__: typing.ClassVar[dict[str, ActuatorHold]]
    fixed: typing.ClassVar[ActuatorHold]
    point: typing.ClassVar[ActuatorHold]
    @typing.overload
    def __eq__(self, other: ActuatorHold) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    @typing.overload
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def __init__(self, name: str) -> None:
        """
        The member a name stands for (as files and strings write it).
        """
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: ActuatorHold) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class RigidBody(Object):
    """
    A rigid body: a shape with mass and a material.
    """
    @property
    def angular_velocity(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        world frame, rad/s
        """
    @angular_velocity.setter
    def angular_velocity(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def center_of_mass(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        world frame
        """
    @property
    def collision_mesh(self) -> str:
        """
        the separate collision mesh file, or '' (the visual mesh collides)
        """
    @property
    def collision_shapes(self) -> list:
        """
        the primitive collision parts as (shape, 4x4 pose in the body frame)
        """
    @property
    def color(self) -> typing.Annotated[list[float], "FixedSize(4)"]:
        """
        RGBA in 0..1
        """
    @color.setter
    def color(self, arg1: typing.Any) -> None:
        ...
    @property
    def damping(self) -> tuple[float, float]:
        """
        (linear, angular), 0..1
        """
    @damping.setter
    def damping(self, arg1: tuple[typing.SupportsFloat | typing.SupportsIndex, typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def dynamic(self) -> bool:
        """
        moved by physics (mass > 0 and not kinematic)
        """
    @property
    def force(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        N at the centre of mass, world frame, applied every step until changed
        """
    @force.setter
    def force(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def friction(self) -> float:
        ...
    @friction.setter
    def friction(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def height(self) -> float:
        ...
    @property
    def inertia(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        principal moments about the centre of mass, kg m^2
        """
    @property
    def inertial_offset(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
        """
        the centre-of-mass frame in the body frame
        """
    @property
    def is_ghost(self) -> bool:
        """
        a ghost object (World.add_ghost)
        """
    @property
    def joints(self) -> list:
        """
        The joints below this body in AMBF's order (every joint reachable from it, creation order, passive ones left out): the order of a root body's joint positions.
        """
    @property
    def kinematic(self) -> bool:
        """
        moved only by setting its pose
        """
    @kinematic.setter
    def kinematic(self, arg1: bool) -> None:
        ...
    @property
    def linear_velocity(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        of the body origin, world frame, m/s
        """
    @linear_velocity.setter
    def linear_velocity(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def mass(self) -> float:
        ...
    @property
    def mesh(self) -> str:
        ...
    @property
    def overlapping(self) -> list:
        """
        a ghost's overlapping bodies after the last step, in creation order: rigid bodies (Bullet's narrow phase) and soft bodies with a node inside its convex parts; ValueError for a body that is not a ghost
        """
    @property
    def radius(self) -> float:
        ...
    @property
    def restitution(self) -> float:
        ...
    @restitution.setter
    def restitution(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def rolling_friction(self) -> float:
        ...
    @rolling_friction.setter
    def rolling_friction(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def shader(self) -> typing.Any:
        """
        the body's own shader (AMBF's body `shaders`): None (its model's), 'builtin' (the engine's own), or (vertex_path, fragment_path); it colours the rgb image only
        """
    @shader.setter
    def shader(self, arg1: typing.Any) -> None:
        ...
    @property
    def shape(self) -> str:
        ...
    @property
    def size(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def torque(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        N m, world frame, applied every step until changed
        """
    @torque.setter
    def torque(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
class Joint(Object):
    """
    A joint between two bodies, with a controller and limits.
    """
    def release(self) -> None:
        """
        stop commanding the joint
        """
    def set_cone_twist_limits(self, twist: typing.SupportsFloat | typing.SupportsIndex, swing_y: typing.SupportsFloat | typing.SupportsIndex, swing_z: typing.SupportsFloat | typing.SupportsIndex) -> None:
        """
        a cone twist joint's twist (about its axis) and swing spans, rad
        """
    def set_effort(self, effort: typing.SupportsFloat | typing.SupportsIndex) -> None:
        """
        apply this effort every step
        """
    def set_position(self, target: typing.SupportsFloat | typing.SupportsIndex) -> None:
        """
        drive to this position with the joint's controller
        """
    def set_velocity(self, target: typing.SupportsFloat | typing.SupportsIndex) -> None:
        """
        drive at this velocity with the joint's motor
        """
    @property
    def anchors(self) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]]:
        """
        the pivot on the parent and on the child, world frame: the joint holds them together
        """
    @property
    def child(self) -> RigidBody:
        ...
    @property
    def child_axis(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def child_offset(self) -> float:
        ...
    @property
    def child_pivot(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        pivot in the child body's frame, m
        """
    @property
    def command(self) -> str:
        ...
    @property
    def command_value(self) -> float:
        ...
    @property
    def controller(self) -> dict:
        """
        {p, i, d, output}; output 'effort' or 'velocity'; assigning updates the keys given
        """
    @controller.setter
    def controller(self, arg1: dict) -> None:
        ...
    @property
    def damping(self) -> float:
        ...
    @damping.setter
    def damping(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def effort(self) -> float:
        """
        effort applied in the last step (controller or command)
        """
    @property
    def limits(self) -> tuple[float | None, float | None]:
        """
        (lower, upper), None where unlimited
        """
    @limits.setter
    def limits(self, arg1: tuple[typing.SupportsFloat | typing.SupportsIndex | None, typing.SupportsFloat | typing.SupportsIndex | None]) -> None:
        ...
    @property
    def offset(self) -> float:
        ...
    @property
    def parent(self) -> RigidBody:
        ...
    @property
    def parent_axis(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def parent_pivot(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        pivot in the parent body's frame, m
        """
    @property
    def passive(self) -> bool:
        ...
    @property
    def position(self) -> float:
        """
        rad or m; 0 where the parent's and child's joint frames coincide
        """
    @property
    def six_dof(self) -> typing.Any:
        """
        a six dof (spring) joint's per-axis settings {lower, upper, stiffness, damping, equilibrium}, 6 values each (x, y, z translation, then x, y, z rotation; a limit None or lower > upper: free); None before any were set; assigning updates the keys given
        """
    @six_dof.setter
    def six_dof(self, arg1: dict) -> None:
        ...
    @property
    def six_dof_coordinates(self) -> typing.Annotated[list[float], "FixedSize(6)"]:
        """
        a six dof (spring) joint's six coordinates now (m, rad)
        """
    @property
    def type(self) -> str:
        ...
    @property
    def velocity(self) -> float:
        """
        rad/s or m/s
        """
class SoftBody(Object):
    """
    A deformable body: Bullet nodes at a mesh's vertices, links along its edges.
    """
    def fix_nodes(self, nodes: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]) -> None:
        """
        Pins nodes (indices) where they are.
        """
    def release_nodes(self, nodes: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]) -> None:
        """
        Lets pinned nodes move again.
        """
    def set_node_positions(self, nodes: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], positions: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 3]"]) -> None:
        """
        Moves nodes (indices) to positions ((K, 3), world frame) at once.
        """
    @property
    def color(self) -> typing.Annotated[list[float], "FixedSize(4)"]:
        """
        RGBA in 0..1
        """
    @color.setter
    def color(self, arg1: typing.Any) -> None:
        ...
    @property
    def config(self) -> dict:
        """
        the AMBF config coefficients it was created with (a copy)
        """
    @property
    def fixed_nodes(self) -> list[int]:
        """
        pinned node indices
        """
    @property
    def margin(self) -> float:
        """
        collision margin, m
        """
    @property
    def mass(self) -> float:
        """
        kg, shared evenly by the nodes
        """
    @property
    def mesh(self) -> str:
        ...
    @property
    def node_count(self) -> int:
        ...
    @property
    def node_velocities(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        (N, 3) float64 node velocities, world frame, m/s (a copy)
        """
    @property
    def nodes(self) -> numpy.ndarray:
        """
        (N, 3) float64 node positions, world frame: a read-only view refreshed by every step (node i is the mesh's i-th distinct vertex)
        """
    @property
    def shader(self) -> typing.Any:
        """
        its own shader: None (its model's), 'builtin', or (vertex_path, fragment_path)
        """
    @shader.setter
    def shader(self, arg1: typing.Any) -> None:
        ...
    @property
    def triangles(self) -> numpy.ndarray:
        """
        (M, 3) uint32 node indices of the faces (read-only view)
        """
class ProximitySensor(Object):
    """
    Rays fixed to a body reporting the nearest body along each.
    """
    def update(self) -> None:
        """
        Casts the rays now (the world does it after every physics step).
        """
    @property
    def distances(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        (N,) m from each ray's start to its hit (its length on a miss)
        """
    @property
    def hits(self) -> list:
        """
        per ray: dict(triggered, distance (m from the ray's start; its length on a miss), fraction, point, normal (world), body (RigidBody, SoftBody or None), node (soft body's nearest node or None))
        """
    @property
    def location(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
        """
        4x4 sensor frame in the parent's frame
        """
    @property
    def parent(self) -> RigidBody:
        ...
    @property
    def range(self) -> float:
        """
        m each ray reaches (per unit of its direction)
        """
    @range.setter
    def range(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def ray_count(self) -> int:
        ...
    @property
    def ray_ends(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        (N, 3) world frame
        """
    @property
    def ray_starts(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        (N, 3) world frame
        """
    @property
    def triggered(self) -> bool:
        """
        whether any ray hits
        """
    @property
    def triggered_rays(self) -> numpy.typing.NDArray[numpy.bool]:
        """
        (N,) bool, whether each ray hits
        """
class ConstraintActuator(Object):
    """
    Holds a body to its parent body on request (a grasp).
    """
    def actuate(self, body: RigidBody, offset: typing.Any = None) -> None:
        """
        Holds body: where it is now, or with the actuator at offset in the body's frame (a point, or a 4x4 frame), pulling it there. A body already held stays held.
        """
    def deactuate(self) -> None:
        """
        Releases the body held.
        """
    def is_actuated(self) -> bool:
        """
        Whether a body is held.
        """
    @property
    def actuated_body(self) -> typing.Any:
        """
        the body held, or None
        """
    @property
    def hold(self) -> str:
        ...
    @property
    def location(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
        """
        4x4 actuator frame in the parent's frame
        """
    @property
    def max_impulse(self) -> float:
        ...
    @property
    def parent(self) -> RigidBody:
        ...
    @property
    def tau(self) -> float:
        ...
class _StateLock:
    """
    The world's state lock, held by a `with` block.
    """
    def __enter__(self) -> None:
        """
        Takes the world's state lock (waiting with the GIL released; the GIL is never waited for while the lock is held).
        """
    def __exit__(self, *args) -> bool:
        """
        Gives the lock back.
        """
class RealTimeLoop:
    """
    Steps a world in real time on its own thread (1 kHz by default, absolute deadlines, SCHED_FIFO where allowed), while other threads capture. Use as a context manager, or start()/stop(). Change the world from Python only inside `with loop.lock():`.
    """
    def __enter__(self) -> RealTimeLoop:
        """
        Starts stepping.
        """
    def __exit__(self, *args) -> bool:
        """
        Stops stepping.
        """
    def __init__(self, world: World, rate: typing.SupportsFloat | typing.SupportsIndex = 1000.0, fifo_priority: typing.SupportsInt | typing.SupportsIndex = 80, cpu: typing.SupportsInt | typing.SupportsIndex = -1, poll_rate: typing.SupportsFloat | typing.SupportsIndex = 100.0) -> None:
        """
        rate: steps per second; fifo_priority: SCHED_FIFO priority to ask for (0: none); cpu: pin to this CPU (-1: the last, only if SCHED_FIFO is refused; -2: never); poll_rate: Hz of the thread serving Python devices and plugins.
        """
    def lock(self) -> typing.Any:
        """
        A context manager holding the world's state lock (the loop waits meanwhile).
        """
    def start(self) -> None:
        """
        Starts stepping (interpreter exit stops it).
        """
    def stop(self) -> None:
        """
        Stops after the step in progress; re-raises an error that stopped a step.
        """
    @property
    def running(self) -> bool:
        ...
    @property
    def scheduling(self) -> str:
        """
        how the loop's thread is scheduled (SCHED_FIFO, or what it fell back to and why)
        """
    @property
    def stats(self) -> dict:
        """
        steps, seconds, mean_rate (Hz), p99 and max period (s), over_2ms (count), step_cpu_p99 (s), lock waits (s), periods (array, s)
        """
class RemovalMode:
    """
    How a drill's burr removes tissue.
    
    Members:
    
      physical
    
      compatible
    """
    __members__: typing.ClassVar[dict[str, RemovalMode]]
    compatible: typing.ClassVar[RemovalMode]
    physical: typing.ClassVar[RemovalMode]
    @typing.overload
    def __eq__(self, other: RemovalMode) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    @typing.overload
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def __init__(self, name: str) -> None:
        """
        The member a name stands for (as files and strings write it).
        """
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: RemovalMode) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class Drill(Object):
    """
    A burr and shaft of finger-proxy cursors that drills a volume.
    """
    MAX_EVENTS: typing.ClassVar[int] = 65536
    MAX_REMOVED: typing.ClassVar[int] = 262144
    on: bool
    def attach(self, body: RigidBody, offset: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"] | None = None) -> None:
        """
        move body with the drill
        """
    def clear_plan(self) -> None:
        """
        removes the plan's fixture (and its attraction, follow_plan)
        """
    def follow_plan(self, *, max_force: typing.SupportsFloat | typing.SupportsIndex = 0.5, start: typing.SupportsFloat | typing.SupportsIndex = 0.002, enabled: bool = True) -> None:
        """
        follow the plan: draws the burr toward the nearest voxel of the plan not yet removed, max_force x min(1, d / start) N for a burr surface d metres from it, fading to zero between 2 x start and 3 x start, none once touching; part of fixture_force, kept passive. Needs a plan (set_plan); clear_plan ends it
        """
    def set_fixture(self, structure: typing.Any, *, start: typing.SupportsFloat | typing.SupportsIndex, max_force: typing.SupportsFloat | typing.SupportsIndex = 1.0, stop: typing.SupportsFloat | typing.SupportsIndex | None = None, enabled: bool = True) -> None:
        """
        sets the forbidden-region fixture of a structure (label name or id), replacing its last: below `start` metres from the burr's surface a force up to `max_force` N at the structure pushes the burr away; below `stop` metres (None: no hard stop) nothing is cut and the burr is held back
        """
    def set_fixtures(self, fixtures: list) -> None:
        """
        replaces every fixture by a list of dicts (a DRILL block's `fixtures`): structure, start, max_force (default 1 N), stop (default None), enabled (default True); [] removes them
        """
    def set_hardness(self, label: typing.SupportsInt | typing.SupportsIndex, hardness: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    def set_plan(self, target: typing.Any, *, start: typing.SupportsFloat | typing.SupportsIndex, max_force: typing.SupportsFloat | typing.SupportsIndex = 1.0, stop: typing.SupportsFloat | typing.SupportsIndex | None = None, enabled: bool = True) -> None:
        """
        stay in the plan: a fixture on the boundary of a planned region, `target` a boolean mask of the volume's shape (nx, ny, nz) or a list of labels (names or ids); every labelled voxel outside it is the forbidden side (with a `stop`, nothing outside it is cut)
        """
    def set_plan_enabled(self, enabled: bool) -> None:
        """
        turns the plan's fixture off or back on, its field kept (set_plan rebuilds it)
        """
    def set_waypoints(self, waypoints: list) -> None:
        """
        follow dicts of time (s from now), pose (4x4) and optionally on and speed, interpolating between them
        """
    def take_events(self) -> list:
        ...
    def take_removed(self) -> dict:
        """
        the voxels removed since the last take, handed over (the drill keeps none)
        """
    @property
    def burr(self) -> int:
        """
        index into burr_diameters
        """
    @burr.setter
    def burr(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def burr_diameters(self) -> list[float]:
        ...
    @property
    def burr_radius(self) -> float:
        ...
    @property
    def critical_distances(self) -> dict:
        """
        metres from the burr's surface to each critical structure
        """
    @property
    def cursor_contacts(self) -> list[int]:
        ...
    @property
    def cursor_goals(self) -> numpy.typing.NDArray[numpy.float64]:
        ...
    @property
    def cursor_proxies(self) -> numpy.typing.NDArray[numpy.float64]:
        ...
    @property
    def cursor_radii(self) -> list[float]:
        ...
    @property
    def cutting_rate(self) -> float:
        """
        m^3 per second per newton at full speed
        """
    @cutting_rate.setter
    def cutting_rate(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def events(self) -> list:
        ...
    @property
    def events_dropped(self) -> int:
        """
        events dropped because nobody took them in time (the newest Drill.MAX_EVENTS are kept)
        """
    @property
    def fixture_force(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        the part of `force` the fixtures added at the last step, N, world frame
        """
    @property
    def fixture_passivity(self) -> bool:
        """
        keep the fixtures' force passive (energy observer and damping; default on)
        """
    @fixture_passivity.setter
    def fixture_passivity(self, arg1: bool) -> None:
        ...
    @property
    def fixtures(self) -> list:
        """
        the fixtures as dicts (set_fixtures' form), structures by label name
        """
    @property
    def follows_plan(self) -> typing.Any:
        """
        the plan's attraction as {max_force, start}, or None when off
        """
    @property
    def force(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        force fed back (the leading cursor's), N, world frame
        """
    @property
    def goal(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
        """
        world from drill where the device puts it (burr centre at the origin, shaft along +x)
        """
    @goal.setter
    def goal(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"]) -> None:
        ...
    @property
    def leading_cursor(self) -> int:
        ...
    @property
    def plan(self) -> typing.Any:
        """
        the plan's fixture as a dict (start, max_force, stop, enabled, voxels), or None
        """
    @property
    def pose(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
        """
        4x4 world from drill (a copy); assigning places the drill there at once, goal and cursors too, as at its creation (assign goal to move it there through the tissue)
        """
    @pose.setter
    def pose(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"]) -> None:
        ...
    @property
    def removal(self) -> str:
        """
        physical or compatible
        """
    @removal.setter
    def removal(self, arg1: RemovalMode | str) -> None:
        ...
    @property
    def removed(self) -> dict:
        """
        voxels removed and not yet taken: dict of step, voxel (N, 3), label (a copy made under the world's lock; take_removed() takes them without copying)
        """
    @property
    def removed_dropped(self) -> int:
        """
        removed voxels dropped because nobody took them in time (the newest Drill.MAX_REMOVED are kept)
        """
    @property
    def speed(self) -> float:
        """
        burr speed, 0..1
        """
    @speed.setter
    def speed(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def stiffness(self) -> float:
        ...
    @stiffness.setter
    def stiffness(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def tick_cpu_seconds(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        thread CPU time of the same ticks, seconds
        """
    @property
    def tick_seconds(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        wall time of recent ticks, seconds
        """
    @property
    def tip_normal(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def total_force(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def volume(self) -> typing.Any:
        ...
class Device:
    """
    A haptic or input device, read once per world step and sent the force to render.
    """
    @property
    def last_force(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        the force last sent to it, N, device frame
        """
    @property
    def spec(self) -> dict:
        """
        name, max_force (N), max_stiffness (N/m), max_damping (N s/m), workspace_radius (m)
        """
class NullDevice(Device):
    """
    No device: at the origin, no buttons, forces ignored.
    """
    def __init__(self) -> None:
        ...
class SimulatedDevice(Device):
    """
    A hand holding a device, simulated: a mass pulled to a target by a spring and damper and pushed by the rendered force, so contact stops it. Deterministic.
    """
    def __init__(self, mass: typing.SupportsFloat | typing.SupportsIndex = 0.1, stiffness: typing.SupportsFloat | typing.SupportsIndex = 100.0, damping: typing.SupportsFloat | typing.SupportsIndex = 2.0, position: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"] = ...) -> None:
        """
        mass (kg), stiffness (N/m) and damping (N s/m) of the hand; its starting position (m).
        """
    def set_target(self, position: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], orientation: typing.Any = None, buttons: typing.SupportsInt | typing.SupportsIndex = 0) -> None:
        """
        Where the hand pulls to (m, device frame), how it holds the handle (quaternion x, y, z, w or 3x3) and the buttons it holds (bit i: button i). Thread-safe.
        """
    @property
    def energy(self) -> float:
        """
        kinetic energy plus the energy in the hand's spring, J
        """
    @property
    def position(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        m, device frame
        """
    @property
    def velocity(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        m/s
        """
class ScriptedDevice(Device):
    """
    A device following waypoints, or a Python callback sampled every `every` steps.
    """
    def __init__(self) -> None:
        ...
    def set_callback(self, callback: collections.abc.Callable, every: typing.SupportsInt | typing.SupportsIndex = 10) -> None:
        """
        callback(time) -> {position, orientation, buttons} or (position[, orientation[, buttons]]), called every `every` steps (in a real-time loop from its low-rate thread); the reading is held in between.
        """
    def set_waypoints(self, waypoints: list) -> None:
        """
        [{time (s after the first step that reads them), position, orientation, buttons}]: positions interpolated linearly, orientations by slerp, buttons as at the last waypoint passed; the last is held.
        """
class KeyboardDevice(Device):
    """
    The keyboard as a device, with the original drilling simulator's bindings: Ctrl+W/S/D/A/I/K move by `step` (up, down, right, left, into and out of the screen of the reference camera), keypad 8/5 and 4/6 turn by `angle`, Space toggles the burr (button 0), C takes the next burr (button 2).
    """
    def __init__(self, step: typing.SupportsFloat | typing.SupportsIndex = 0.001, angle: typing.SupportsFloat | typing.SupportsIndex = 0.05235987755982988) -> None:
        ...
    def key(self, key: typing.SupportsInt | typing.SupportsIndex, action: typing.SupportsInt | typing.SupportsIndex, mods: typing.SupportsInt | typing.SupportsIndex) -> bool:
        """
        A key event (GLFW key code, action 0 release / 1 press / 2 repeat, modifier bits); True when it is one of the device's keys.
        """
    def set_state(self, state: typing.Any) -> None:
        """
        Sets the reading ({position, orientation, buttons}).
        """
class NetworkDevice(Device):
    """
    A device on the network: a bridge sends 80-byte UDP pose datagrams and gets 48-byte force datagrams back after every step (format in ambfplus/haptics/device.h and README); bound to loopback unless another address is given. Malformed, oversized or stale messages are rejected and counted.
    """
    def __init__(self, port: typing.SupportsInt | typing.SupportsIndex = 0, address: str = '127.0.0.1', max_distance: typing.SupportsFloat | typing.SupportsIndex = 10.0) -> None:
        ...
    @property
    def accepted(self) -> int:
        """
        poses accepted
        """
    @property
    def port(self) -> int:
        """
        the bound UDP port
        """
    @property
    def rejected(self) -> dict:
        """
        messages rejected, by reason (size, magic, version, values, range, rotation, sequence)
        """
class JoystickMapping:
    """
    Which joystick buttons and axes do what.
    """
    def __init__(self, drill: typing.SupportsInt | typing.SupportsIndex = 0, clutch: typing.SupportsInt | typing.SupportsIndex = 1, burr: typing.SupportsInt | typing.SupportsIndex = 2, axes: typing.Annotated[collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], "FixedSize(3)"] = [0, 1, -1], speed: typing.SupportsFloat | typing.SupportsIndex = 0.02, deadband: typing.SupportsFloat | typing.SupportsIndex = 0.05) -> None:
        ...
    @property
    def axes(self) -> typing.Annotated[list[int], "FixedSize(3)"]:
        ...
    @property
    def burr(self) -> int:
        ...
    @property
    def clutch(self) -> int:
        ...
    @property
    def deadband(self) -> float:
        ...
    @property
    def drill(self) -> int:
        ...
    @property
    def speed(self) -> float:
        ...
class JoystickDevice(Device):
    """
    A joystick, gamepad or foot pedal through the Linux joystick interface (/dev/input/jsN): buttons spin the burr (held), clutch (held) or take the next burr (pressed); axes move the device. Without a path, events come only from feed().
    """
    def __init__(self, path: str = '', mapping: JoystickMapping = ...) -> None:
        ...
    def feed(self, events: bytes) -> None:
        """
        Linux js_event records (8 bytes each: uint32 time ms, int16 value, uint8 type, uint8 number), as read from the device file.
        """
    @property
    def disconnected(self) -> bool:
        """
        the device file failed (unplugged): every button is released
        """
    @property
    def mapping(self) -> JoystickMapping:
        ...
class MergedDevice(Device):
    """
    A pose from one device and buttons from others (a haptic device with a foot pedal).
    """
    def __init__(self, pose: Device, buttons: collections.abc.Sequence[Device]) -> None:
        ...
class ReplayDevice(Device):
    """
    Plays back the readings of an InputDevice's log, step by step.
    """
    def __init__(self, log: dict) -> None:
        """
        log: {step, position, orientation, buttons} (InputDevice.log).
        """
    @property
    def steps_past_end(self) -> int:
        """
        steps read after the last logged one
        """
class InputDevice(Object):
    """
    A device bound to a drill: its motion moves the drill's goal (workspace scale, clutch, the reference's axes), its buttons turn and change the burr, the drill's force goes back; every reading is logged with its step.
    """
    MAX_LOG: typing.ClassVar[int] = 65536
    def take_log(self) -> dict:
        """
        Hands over the readings logged so far and starts a new log.
        """
    @property
    def clutched(self) -> bool:
        ...
    @property
    def device(self) -> Device:
        ...
    @property
    def drill(self) -> Drill:
        ...
    @property
    def force(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        the force sent to the device after the last step, N, device frame
        """
    @property
    def log(self) -> dict:
        """
        readings since the last take_log(): step, position, orientation, buttons
        """
    @property
    def log_dropped(self) -> int:
        """
        readings dropped because nobody took them in time (the newest InputDevice.MAX_LOG are kept)
        """
    @property
    def state(self) -> dict:
        """
        the last reading: position (m), orientation (x, y, z, w), buttons
        """
class LoadReport:
    """
    What loading a launch file did.
    """
    def __repr__(self) -> str:
        ...
    @property
    def errors(self) -> list:
        """
        (file, message) for every model or device that did not load
        """
    @property
    def input_devices(self) -> list:
        ...
    @property
    def launch(self) -> dict:
        ...
    @property
    def models(self) -> list:
        """
        the models loaded (the world's environment first)
        """
    @property
    def warnings(self) -> list:
        """
        (file, message) for everything loaded with a caveat (unknown keys, dangling references, defaults taken)
        """
class SkillMetrics:
    """
    Skill metrics of a drilling session, fed tick by tick (live) or from a recording (offline) through the same code.
    """
    def __init__(self, volume: VolumeData, *, protect: list = [], target_labels: typing.Any = None, target_mask: typing.Any = None, excess_force: typing.SupportsFloat | typing.SupportsIndex = 3.0, stroke_gap: typing.SupportsFloat | typing.SupportsIndex = 0.05, turn_step: typing.SupportsFloat | typing.SupportsIndex = 0.0005, turn_angle: typing.SupportsFloat | typing.SupportsIndex = 0.7853981633974483, field_band: typing.SupportsFloat | typing.SupportsIndex = 0.005, apply_removals: bool = False) -> None:
        """
        Metrics of drilling `volume` (the volume being drilled, which the structures' distance fields follow). protect: [{'name', 'labels': names or ids, 'margin': metres}]; target_labels: the labels of the target region, or target_mask: the region voxel by voxel (an array of the volume's shape, non-zero inside); excess_force: N; stroke_gap: s; turn_step: m; turn_angle: rad; field_band: m beyond the margins; apply_removals: remove each tick's voxels from `volume` (offline, on a fresh copy of the anatomy).
        """
    def add(self, step: typing.SupportsInt | typing.SupportsIndex, time: typing.SupportsFloat | typing.SupportsIndex, dt: typing.SupportsFloat | typing.SupportsIndex, tip: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], force: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], burr_radius: typing.SupportsFloat | typing.SupportsIndex, burr_on: bool, removed: typing.Annotated[numpy.typing.ArrayLike, numpy.int32] | None = None, removed_labels: typing.Annotated[numpy.typing.ArrayLike, numpy.uint16] | None = None) -> None:
        """
        Adds one tick: the burr centre `tip` (volume frame), the force on the hand, and the voxels removed during it (M, 3) with the labels they had (M,).
        """
    def add_ticks(self, steps: typing.Annotated[numpy.typing.ArrayLike, numpy.int64], times: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], dt: typing.SupportsFloat | typing.SupportsIndex, tips: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], forces: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], burr_radii: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], burr_on: typing.Annotated[numpy.typing.ArrayLike, numpy.bool], removed_tick: typing.Annotated[numpy.typing.ArrayLike, numpy.int64], removed: typing.Annotated[numpy.typing.ArrayLike, numpy.int32], removed_labels: typing.Annotated[numpy.typing.ArrayLike, numpy.uint16], fields_taken: typing.Annotated[numpy.typing.ArrayLike, numpy.float64] | None = None) -> None:
        """
        Adds N ticks at once (a recording's): steps (N,), times (N,), tips and forces (N, 3), burr radii and burr on (N,), and the removed voxels (M, 3) with their labels (M,) and the index of the tick that removed each (M,), sorted. fields_taken: a real-time session's step-log column '<drill>.metrics_fields' (N, W): the protected structures' updated fields are taken at those ticks, as live.
        """
    def clearance(self, structure: typing.SupportsInt | typing.SupportsIndex, point: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], radius: typing.SupportsFloat | typing.SupportsIndex) -> float:
        """
        Distance (metres) from a sphere at `point` (volume frame) to the protected structure with this index, from its field as of the last tick.
        """
    def summary(self) -> dict:
        """
        Everything measured so far, as a dict (distances in metres, times in seconds, forces in newtons, volumes as voxel counts with voxel_volume in cubic metres).
        """
class LiveMetrics:
    """
    Skill metrics of a drill measured live: its world feeds them at every step, through the code the offline assessment runs (ambfplus.live_metrics starts them).
    """
    def clearances(self) -> list:
        """
        Each protected structure's distance (metres; None once it is gone) from the burr where it is now, with its margin: [{'name', 'margin', 'distance'}].
        """
    def summary(self) -> dict:
        """
        The metrics so far, as SkillMetrics.summary() gives them.
        """
    @property
    def active(self) -> bool:
        """
        Whether the metrics are still fed (their drill is in the world).
        """
    @property
    def field_waits(self) -> dict:
        """
        How often a tick waited for a structure's field brought up to date after a breach (due kFollowTicks ticks after it, as offline, so that the live metrics equal the offline assessment), and the seconds waited: {'count', 'seconds'}; zero on a machine that keeps up.
        """
    @property
    def tick_cpu_seconds(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        CPU seconds the metrics added to each of the last ticks (up to 16384).
        """
class DrillSound:
    """
    A drill's live sound, synthesised from the burr's state (spin-up and coasting, motor pitch falling with load, cutting noise following the tissue's hardness and the removal rate, proximity beeps) and fed from the drill at every step of its world, by the haptic thread of a real-time loop. Plays through miniaudio; a machine without an audio device says so once (a warning) and carries on silent. Use as a context manager, or close().
    """
    def __enter__(self) -> DrillSound:
        ...
    def __exit__(self, *args) -> bool:
        ...
    def __init__(self, drill: Drill, *, output: str = 'device', muted: bool = False, require_device: bool = False, warnings: typing.Any = None, hardness: typing.Any = None, sample_rate: typing.SupportsInt | typing.SupportsIndex = 48000, period_frames: typing.SupportsInt | typing.SupportsIndex = 128, max_backlog_ticks: typing.SupportsInt | typing.SupportsIndex = 16, trim_backlog: bool = True, paused: bool = False, capture_seconds: typing.SupportsFloat | typing.SupportsIndex = 0.0, seed: typing.SupportsInt | typing.SupportsIndex = 24301) -> None:
        """
        output: 'device' (the default output: PulseAudio, ALSA or JACK), 'null' (miniaudio's null device: played at the real rate, heard by nobody; it wakes every 10 ms), 'virtual' (a sound card with no hardware: asks for each period at its deadline on its own clock, heard by nobody) or 'none'. require_device: raise ResourceError instead of carrying on silent. warnings: None (a beep per critical label of the volume, from 1 mm) or {structure: start metres, or {start, full, frequency, slow_period, fast_period}}; {} for none. hardness: {structure: hardness relative to bone} (1 elsewhere). max_backlog_ticks, trim_backlog: ticks beyond what the next callback needs, and a backlog that never drains, are dropped (bounded latency). paused: open the device without starting it. capture_seconds: keep that much of what is played for take_capture().
        """
    def close(self) -> None:
        """
        Stops feeding and closes the device; idempotent.
        """
    def set_muted(self, muted: bool) -> None:
        ...
    def take_capture(self) -> numpy.typing.NDArray[numpy.float32]:
        """
        The samples played since the last take (capture_seconds of them at most).
        """
    def take_latencies(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        Seconds from each tick's push (the haptic step) to the moment its first sample is written into the device's buffer, for the ticks played since the last take.
        """
    def toggle_mute(self) -> bool:
        """
        Mutes or unmutes (a launcher's mute key); returns whether it is now muted.
        """
    @property
    def backend(self) -> str:
        """
        the backend playing ('pulseaudio', 'alsa', 'jack', 'null', 'virtual'; '' for none)
        """
    @property
    def closed(self) -> bool:
        ...
    @property
    def device_error(self) -> typing.Any:
        """
        why no device plays (None when one does or none was asked for)
        """
    @property
    def drill(self) -> Drill:
        """
        the drill it follows
        """
    @property
    def muted(self) -> bool:
        """
        silences the output (the sound keeps running underneath)
        """
    @muted.setter
    def muted(self, arg1: bool) -> None:
        ...
    @property
    def paused(self) -> bool:
        """
        stops or restarts the device; ticks queue meanwhile
        """
    @paused.setter
    def paused(self, arg1: bool) -> None:
        ...
    @property
    def period_frames(self) -> int:
        """
        frames per audio callback the device settled on
        """
    @property
    def playing(self) -> bool:
        """
        whether a device (or the null or virtual device) plays
        """
    @property
    def sample_rate(self) -> int:
        ...
    @property
    def stats(self) -> dict:
        """
        ticks pushed, rejected (queue full), played, dropped (backlog), held (repeated while none arrived); callbacks and frames played
        """
    @property
    def warnings(self) -> list:
        """
        the proximity warnings, in the order of their distances
        """
class PluginSite:
    """
    Where a Python plugin is attached (its `_site`); handles are made on each access, so keep names on a plugin rather than handles.
    """
    @property
    def file(self) -> str:
        """
        the file it came from
        """
    @property
    def model(self) -> typing.Any:
        """
        the model (model scope) or the object's model (object scope), else None
        """
    @property
    def name(self) -> str:
        """
        the declared name
        """
    @property
    def object(self) -> typing.Any:
        """
        the object (object scope), else None
        """
    @property
    def scope(self) -> str:
        """
        'simulator', 'world', 'model' or 'object'
        """
    @property
    def simulator(self) -> Simulator:
        ...
    @property
    def world(self) -> World:
        ...
class PluginInfo:
    """
    A plugin attached to a world (a snapshot).
    """
    def __repr__(self) -> str:
        ...
    @property
    def attached_to(self) -> typing.Any:
        """
        the simulator, world, model or object it belongs to
        """
    @property
    def enabled(self) -> bool:
        """
        False once a hook of it raised
        """
    @property
    def file(self) -> str:
        """
        the file it was loaded from
        """
    @property
    def instance(self) -> typing.Any:
        """
        the Python plugin object, or None
        """
    @property
    def language(self) -> str:
        """
        'c++' or 'python'
        """
    @property
    def name(self) -> str:
        ...
    @property
    def scope(self) -> str:
        """
        'simulator', 'world', 'model' or 'object'
        """
def _register_plugin_support(arg0: typing.Any, arg1: typing.Any, arg2: typing.Any) -> None:
    """
    Called once by ambfplus.plugin: the Plugin base class and the functions making Python plugins from a file and from an entry-point name.
    """
def burr_in_volume(world_from_volume: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], burr_in_world: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> numpy.typing.NDArray[numpy.float64]:
    """
    The burr centres (N, 3, world) in the frame of the volume at world_from_volume (4x4): the live metrics' own computation, so that an offline replay sees the same bits.
    """
def capture_passes() -> list:
    """
    The capture passes, in order: dicts of name, dtype (NumPy's name), channels (1: an (H, W) image, 3: (H, W, 3)), rendered (drawn by the GPU, else computed from other passes), default (made when a camera is not told otherwise) and description
    """
def gl_info() -> dict:
    """
    Describes the OpenGL context (created on first use): vendor, renderer, version, ...
    """
def live_metrics(drill: Drill, *, protect: list = [], target_labels: typing.Any = None, target_mask: typing.Any = None, excess_force: typing.SupportsFloat | typing.SupportsIndex = 3.0, stroke_gap: typing.SupportsFloat | typing.SupportsIndex = 0.05, turn_step: typing.SupportsFloat | typing.SupportsIndex = 0.0005, turn_angle: typing.SupportsFloat | typing.SupportsIndex = 0.7853981633974483, field_band: typing.SupportsFloat | typing.SupportsIndex = 0.005) -> LiveMetrics:
    """
    Starts skill metrics of `drill`, fed by its world after every step (SkillMetrics' options); its world keeps them until it goes.
    """
def load_nrrd(path: os.PathLike | str | bytes, kind: str = 'auto', threshold: typing.SupportsFloat | typing.SupportsIndex | None = None) -> VolumeData:
    """
    Loads an NRRD label map, intensity volume (segmented by threshold) or 3D Slicer segmentation (.seg.nrrd).
    """
def load_slice_stack(folder: os.PathLike | str | bytes, prefix: str = 'plane00', format: str = 'png', count: typing.SupportsInt | typing.SupportsIndex = -1, *, dimensions: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"] | None = None, voxel_size: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"] | None = None, labels: typing.Any = None, alpha_threshold: typing.SupportsInt | typing.SupportsIndex = 128) -> VolumeData:
    """
    Loads an AMBF slice stack: pixel (row r, column c) of slice k is voxel (c, H-1-r, k).
    """
def openxr_built() -> bool:
    """
    True when this build has OpenXR sessions (OpenXR's headers were there at build time).
    """
def phantom(resolution: typing.SupportsInt | typing.SupportsIndex = 128, seed: typing.SupportsInt | typing.SupportsIndex = 0, side: str = 'right') -> VolumeData:
    """
    The built-in procedural temporal bone (48 mm cube, lateral face towards +z; side "right" or "left"), labelled like the original system's segmented ear.
    """
def plugin_search_path() -> list[str]:
    """
    The folders searched for a plugin after its declaration's own path: AMBFPLUS_PLUGIN_PATH, then the package's plugin folder.
    """
def read_colors(path: os.PathLike | str | bytes) -> dict[str, typing.Annotated[list[float], "FixedSize(4)"]]:
    """
    A colour file's named colours as RGBA in 0..1.
    """
def read_input_devices(path: os.PathLike | str | bytes) -> list:
    """
    The devices an input-devices file lists, as dicts, in order.
    """
def read_label_table(path: os.PathLike | str | bytes) -> list[Label]:
    ...
def read_launch(path: os.PathLike | str | bytes) -> dict:
    """
    A launch file's entries as a dict, paths made absolute.
    """
def render_drill_sound(on: typing.Any, load: typing.Any = None, removal_rate: typing.Any = None, *, speed: typing.Any = None, hardness: typing.Any = None, distances: typing.Any = None, warnings: typing.Any = None, sample_rate: typing.SupportsInt | typing.SupportsIndex = 48000, tick_seconds: typing.SupportsFloat | typing.SupportsIndex = 0.001, seed: typing.SupportsInt | typing.SupportsIndex = 24301) -> numpy.typing.NDArray[numpy.float32]:
    """
    The drill sound of a tick sequence, offline: mono float32 samples at sample_rate, exactly what a DrillSound plays for the same ticks (one synthesiser). on: burr on per tick; load: N; removal_rate: m^3/s; speed: 0..1 (1); hardness: relative to bone (1); warnings: {name: start metres or {start, full, frequency, slow_period, fast_period}} with distances (ticks, len(warnings)) in metres. Deterministic.
    """
def use_x11_display(display: typing.SupportsInt | typing.SupportsIndex) -> None:
    """
    Puts the engine's OpenGL context on this X11 display (the address of a Display*, e.g. GLFW's glfwGetX11Display()), so windows can show cameras. Call before anything renders.
    """
def write_image(path: str, image: numpy.ndarray) -> None:
    """
    Writes an (H, W) grey, (H, W, 3) RGB or (H, W, 4) RGBA uint8/uint16 image; the extension picks the format (.png keeps uint16).
    """
def write_label_table(path: os.PathLike | str | bytes, labels: collections.abc.Sequence[Label]) -> None:
    ...
DRILL_SOUND_MAX_WARNINGS: int = 16
MAX_ANTIALIASING: int = 4
PLUGIN_ABI_VERSION: int = 2
__version__: str = '0.1.0'
