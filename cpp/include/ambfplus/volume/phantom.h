#pragma once

#include <cstdint>
#include <memory>

#include "ambfplus/export.h"
#include "ambfplus/volume/volume_data.h"

namespace ambfplus {

/// A procedural temporal-bone phantom: a block of bone with mastoid air cells, the sigmoid sinus
/// and dura, the facial nerve in its canal, the labyrinth with three semicircular canals and the
/// cochlea, the ossicles, the external auditory canal, the internal carotid artery and the chorda
/// tympani. Deterministic for a seed, at any resolution; 48 mm across like the fixture ear, with
/// the lateral surface (where drilling starts) facing +z.
AMBFPLUS_API std::shared_ptr<VolumeData> make_temporal_bone_phantom(int resolution = 128,
                                                                    std::uint32_t seed = 0);

/// The phantom's label table (ids 1..10).
AMBFPLUS_API LabelTable phantom_label_table();

}  // namespace ambfplus
