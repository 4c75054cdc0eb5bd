#pragma once
// The program's identity for checkpoints: "VERSION COMMIT" (docs/getting-started.md, resume).

namespace vdmsim {

const char* program_version();

}  // namespace vdmsim
