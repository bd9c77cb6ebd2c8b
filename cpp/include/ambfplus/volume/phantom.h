#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "ambfplus/export.h"
#include "ambfplus/volume/volume_data.h"

namespace ambfplus {

/// Which ear a phantom is: a left ear mirrors a right one across the sagittal plane.
enum class PhantomSide { kRight, kLeft };

/// "right" or "left" as a PhantomSide; throws ArgumentError naming the value otherwise.
AMBFPLUS_API PhantomSide parse_phantom_side(const std::string& side);

/// A procedural temporal-bone phantom built from the anatomy's landmarks: mastoid cortex with
/// its tip, the suprameatal spine and the zygomatic root; the external auditory canal opening
/// laterally; the tegmen under the middle-fossa dura; the sigmoid sinus and posterior-fossa
/// dura; pneumatised air cells; the facial nerve and chorda tympani; the bony labyrinth
/// (vestibule, three semicircular canals, cochlea) and vestibular aqueduct; the ossicles; the
/// internal auditory canal with the vestibular and cochlear nerves; the internal carotid artery;
/// the temporomandibular joint. The seed varies sizes, pneumatisation and positions within
/// anatomical ranges; deterministic for a seed, at any resolution. 48 mm across like the fixture
/// ear, centred on the origin, x anterior (right ear; posterior for a left one), y superior and
/// the lateral surface (where drilling starts, z = +16 mm) facing +z. Its label table is the
/// original system's (phantom_label_table()). Throws ArgumentError for a resolution outside
/// 16..2048.
AMBFPLUS_API std::shared_ptr<VolumeData> make_temporal_bone_phantom(
    int resolution = 128, std::uint32_t seed = 0, PhantomSide side = PhantomSide::kRight);

/// The phantom's label table: the names, ids (1..16) and colours of the original system's
/// segmented ear and its labels.csv, with removable and critical flags for drilling.
AMBFPLUS_API LabelTable phantom_label_table();

}  // namespace ambfplus
