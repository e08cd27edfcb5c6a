#pragma once
// The one place where a run's Outcome becomes the process exit status
// (README "Exit status"); the layers below src/app/ only return outcomes.
#include "render/Outcome.h"

namespace vkrt {

/// Prints the outcome's messages to stderr and returns its exit code.
int exitCodeFor(const Outcome& outcome);

} // namespace vkrt
