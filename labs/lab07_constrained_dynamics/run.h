#pragma once
// Lab 07 — given code: the driver's live mode (main.cpp keeps the flags, one
// run and the comparison): the scene's constrained steps beside a page in the
// browser (common/live.h; docs/DESIGN.md §3, "The live mode").
#include <string>

#include "common/cli.h"
#include "common/live.h"
#include "experiments.h"

namespace cl::lab07 {

// Steps --scene (with --stiffness, --regularize) by --method until the page
// or a signal stops it. Knobs: dt; stabilize (0 or 1: --stabilize's
// projection after every step); k (every spring's stiffness, N/m; only when
// the springs are finite). A pin or a held particle changes the unknowns: the
// step after it gathers them again.
int run_live_scene(const char* lab_name, const std::string& scene_dir, const CommonOptions& options,
                   const LabOptions& lab, const LiveOptions& live);

}  // namespace cl::lab07
