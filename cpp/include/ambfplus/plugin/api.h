#ifndef AMBFPLUS_PLUGIN_API_H
#define AMBFPLUS_PLUGIN_API_H

/* What a plugin may ask of the engine: C functions of libambfplus over opaque handles and plain
 * data (ids, numbers, double[16] poses, strings), so a plugin built with other compiler flags
 * than the engine (vectorisation, optimisation, another compiler) sees the same data. Nothing
 * here lays out an engine class. ambfplus/plugin/plugin.h wraps it for C++.
 *
 * Conventions:
 * - A world is an AmbfplusWorld*; an object of it is its AmbfplusId (> 0, never reused), 0
 *   meaning none.
 * - Poses are 4x4 row-major double[16], world from object; positions and forces in metres and
 *   newtons, world frame.
 * - A call that fails returns -1 (or 0 for an id, NULL for a string) and leaves its reason in
 *   ambfplus_last_error(), which names the object, property or key and what was expected.
 * - Strings the engine returns stay valid while the object (or world) they belong to lives.
 * - Calls are made from plugin hooks, which run with the world's state lock held; from a
 *   thread of the plugin's own, take the lock first (ambfplus_world_lock).
 */

#include <stddef.h>
#include <stdint.h>

#include "ambfplus/export.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A world, opaque. */
typedef struct AmbfplusWorld AmbfplusWorld;
/** An object of a world: its id (> 0). */
typedef int32_t AmbfplusId;

/** Object kinds (ambfplus::ObjectKind's order). */
enum AmbfplusKind {
  AMBFPLUS_ANY = -1,
  AMBFPLUS_BODY = 0,
  AMBFPLUS_JOINT = 1,
  AMBFPLUS_CAMERA = 2,
  AMBFPLUS_LIGHT = 3,
  AMBFPLUS_VOLUME = 4,
  AMBFPLUS_DRILL = 5,
  AMBFPLUS_SOFT_BODY = 6,
  AMBFPLUS_SENSOR = 7,
  AMBFPLUS_ACTUATOR = 8,
  AMBFPLUS_INPUT_DEVICE = 9
};

/** Log levels (ambfplus::LogLevel's values). */
enum AmbfplusLogLevel {
  AMBFPLUS_DEBUG = 10,
  AMBFPLUS_INFO = 20,
  AMBFPLUS_WARNING = 30,
  AMBFPLUS_ERROR = 40
};

/** One option of ambfplus_world_add: a key with numbers or a text. */
typedef struct AmbfplusOption {
  const char* key;      /**< "radius", "burr_diameters", ... */
  const double* values; /**< count numbers (NULL with count 0 for a text option) */
  int count;
  const char* text; /**< a text value ("sphere", "physical", a volume's name), else NULL */
} AmbfplusOption;

/** Why the last call on this thread failed ("" when none did). */
AMBFPLUS_API const char* ambfplus_last_error(void);

/** Logs a message through the engine's log. */
AMBFPLUS_API void ambfplus_log(int level, const char* message);

/* ---- The world ---------------------------------------------------------------------------- */

/** Holds the world's state lock (recursive) until the matching unlock: what a plugin's own
 * thread does before it calls into the world. Hooks run with it held already. */
AMBFPLUS_API void ambfplus_world_lock(const AmbfplusWorld* world);
AMBFPLUS_API void ambfplus_world_unlock(const AmbfplusWorld* world);

/** Simulation time (s), step index and fixed step (s). */
AMBFPLUS_API double ambfplus_world_time(const AmbfplusWorld* world);
AMBFPLUS_API int64_t ambfplus_world_step_index(const AmbfplusWorld* world);
AMBFPLUS_API double ambfplus_world_time_step(const AmbfplusWorld* world);
/** The world's name. */
AMBFPLUS_API const char* ambfplus_world_name(const AmbfplusWorld* world);
/** The command-line arguments meant for simulator plugins (AMBF passes on those it does not
 * know): their count, and argument i. */
AMBFPLUS_API int ambfplus_world_argument_count(const AmbfplusWorld* world);
AMBFPLUS_API const char* ambfplus_world_argument(const AmbfplusWorld* world, int index);
/** Objects in creation order: their count, and the id of object i. */
AMBFPLUS_API int ambfplus_world_object_count(const AmbfplusWorld* world);
AMBFPLUS_API AmbfplusId ambfplus_world_object(const AmbfplusWorld* world, int index);
/** The object with exactly this name (of this kind, or AMBFPLUS_ANY), else 0. */
AMBFPLUS_API AmbfplusId ambfplus_world_find(const AmbfplusWorld* world, const char* name, int kind);
/** Objects a name refers to as AMBF finds them ("l1", "/ambf/env/l1", "BODY l1", a unique part
 * of a name; an exact name first; of several, joints dropped when no kind is asked for and that
 * leaves one), by the same rules as Python's World.get (ambfplus/scene/names.h): writes up to
 * capacity ids and returns how many match. */
AMBFPLUS_API int ambfplus_world_lookup(const AmbfplusWorld* world, const char* query, int kind,
                                       AmbfplusId* ids, int capacity);
/** Creates an object of kind "body", "ghost" (a ghost object: a body's options, no collision
 * response, overlaps reported) or "drill" named name in the model named model (NULL: the
 * world's own; a new model of that name when there is none), from options with the keyword
 * names of ambfplus's Python add_body / add_drill (a drill's "volume" is a volume's name).
 * Returns its id. */
AMBFPLUS_API AmbfplusId ambfplus_world_add(AmbfplusWorld* world, const char* model,
                                           const char* kind, const char* name,
                                           const AmbfplusOption* options, int count);

/* ---- Objects ------------------------------------------------------------------------------ */

/** An object's kind (enum AmbfplusKind), or -1 for an id of no object. */
AMBFPLUS_API int ambfplus_object_kind(const AmbfplusWorld* world, AmbfplusId object);
/** Its name, and the name of its model. */
AMBFPLUS_API const char* ambfplus_object_name(const AmbfplusWorld* world, AmbfplusId object);
AMBFPLUS_API const char* ambfplus_object_model(const AmbfplusWorld* world, AmbfplusId object);
/** World from object, row-major. */
AMBFPLUS_API int ambfplus_object_pose(const AmbfplusWorld* world, AmbfplusId object,
                                      double pose[16]);
AMBFPLUS_API int ambfplus_object_set_pose(AmbfplusWorld* world, AmbfplusId object,
                                          const double pose[16]);
/** A property of an object (cpp/README.md, "Plugins", lists them by kind: a body's "color",
 * "visible", "kinematic", "force"; a drill's "goal", "burr", "cursor_proxies"; ...): writes up
 * to capacity values and returns how many it has (call again with more room when that is more
 * than capacity). */
AMBFPLUS_API int ambfplus_object_get(const AmbfplusWorld* world, AmbfplusId object,
                                     const char* property, double* values, int capacity);
/** Sets a property from count values; returns 0. */
AMBFPLUS_API int ambfplus_object_set(AmbfplusWorld* world, AmbfplusId object, const char* property,
                                     const double* values, int count);
/** Makes object move with parent, at local (parent from object, row-major; NULL: where it is
 * now). A body attached to a drill is carried by it (and stops colliding with its cursors);
 * anything else rides on its parent after every step. Parent 0 detaches. */
AMBFPLUS_API int ambfplus_object_attach(AmbfplusWorld* world, AmbfplusId object, AmbfplusId parent,
                                        const double local[16]);

/* ---- Ghost objects ------------------------------------------------------------------------ */

/** The bodies overlapping a ghost object after the last step (rigid bodies by Bullet's narrow
 * phase, soft bodies with a node inside its convex parts), in creation order: writes up to capacity
 * ids and returns how many there are (-1 when ghost is not a ghost object). Added in ABI 2 without
 * changing it: a plugin that calls it needs an engine that has it. */
AMBFPLUS_API int ambfplus_ghost_overlaps(const AmbfplusWorld* world, AmbfplusId ghost,
                                         AmbfplusId* ids, int capacity);

/* ---- Volumes ------------------------------------------------------------------------------ */

/** Names a volume's labels from a label file (CSV or YAML, e.g. the original system's
 * labels.csv): each label becomes the file's label of the nearest colour (voxels relabelled),
 * and what the volume resets to. */
AMBFPLUS_API int ambfplus_volume_name_labels(AmbfplusWorld* world, AmbfplusId volume,
                                             const char* label_file);
/** Marks critical structures unless some are already marked: labels named like nerves,
 * vessels, the sinus and dura, the labyrinth or the IAC, else every label but the commonest. */
AMBFPLUS_API int ambfplus_volume_mark_critical(AmbfplusWorld* world, AmbfplusId volume);

#ifdef __cplusplus
}
#endif

#endif /* AMBFPLUS_PLUGIN_API_H */
