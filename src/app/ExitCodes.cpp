#include "app/ExitCodes.h"

#include "app/Commands.h"

#include <cstdio>

namespace vkrt {

namespace {

int exitCodeOf(OutcomeKind kind)
{
    switch (kind) {
    case OutcomeKind::Passed: return kExitOk;
    case OutcomeKind::Failed: return kExitCompareFailed;
    case OutcomeKind::BadInput: return kExitBadInput;
    case OutcomeKind::DeviceFailure: return kExitFailure;
    case OutcomeKind::ValidationMessages: return kExitValidation;
    case OutcomeKind::Interrupted: return kExitInterrupted;
    }
    return kExitFailure;
}

} // namespace

int exitCodeFor(const Outcome& outcome)
{
    for (const std::string& message : outcome.messages) std::fprintf(stderr, "%s\n", message.c_str());
    return exitCodeOf(outcome.kind);
}

} // namespace vkrt
