#pragma once
// The CFD air a command reads from its --cfd flag: a folder of cases (the production cases of
// data/cfd/, interpolated between tilts) or one case's JSON header (that case alone, e.g. the
// held-out tilt 37.5 deg, which a folder never serves).

#include <string>

#include "models/cfd_field.h"

namespace airtwin::cli {

/// A folder: CfdField::read_dir (mesh level 1, 20 mm inlet, held-out case left out). A `.json`
/// file: the CFD field of that case only (its tilt alone). InputError naming the path otherwise.
CfdField read_cfd_source(const std::string& path);

}  // namespace airtwin::cli
