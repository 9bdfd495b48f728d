#pragma once
// Lab 09 — given code: the driver's live mode (main.cpp keeps the flags, one
// run and the experiment): the scene's steps with or without K_g beside a page
// in the browser (common/live.h; docs/DESIGN.md §3, "The live mode").
#include <string>

#include "common/cli.h"
#include "common/live.h"
#include "experiments.h"

namespace cl::lab09 {

// Steps --scene by --method (with --compression, --regularize) until the page
// or a signal stops it. Knobs: dt; Kg (1: the geometric stiffness in the step,
// 0: lab 07's step; --geometric-stiffness's value to start); k (every spring's
// stiffness, N/m; only when the springs are finite). A change of one, a pin or
// a held particle gathers the unknowns again and forgets the previous step's
// multipliers (the next K_g comes from a first solve without it).
int run_live_scene(const char* lab_name, const std::string& scene_dir, const CommonOptions& options,
                   const LabOptions& lab, const LiveOptions& live);

}  // namespace cl::lab09
