#pragma once
// How a command's run ended, as the layers below src/app/ report it. Only
// src/app/ turns an Outcome into a process exit code (README "Exit status").
#include <string>
#include <utility>
#include <vector>

namespace vkrt {

enum class OutcomeKind {
    Passed,             ///< everything asked for was done (and every test passed)
    Failed,             ///< a test failed (a regression case, a comparison)
    BadInput,           ///< a scene, option, suite or image was wrong
    DeviceFailure,      ///< the GPU, the driver or vkrt itself failed
    ValidationMessages, ///< the Vulkan validation layer reported something
    Interrupted         ///< SIGINT; what had finished was kept
};

/// An OutcomeKind with the messages the caller has still to show the user
/// (messages already printed while running are not repeated here).
struct Outcome {
    OutcomeKind kind = OutcomeKind::Passed;
    std::vector<std::string> messages;

    static Outcome passed() { return {}; }
    static Outcome of(OutcomeKind kind, std::vector<std::string> messages = {}) { return {kind, std::move(messages)}; }
    bool ok() const { return kind == OutcomeKind::Passed; }
};

/// Any validation message makes the run's outcome ValidationMessages (as
/// `vkrt render` always did): a kernel or API misuse taints every result.
inline Outcome withValidation(Outcome outcome, const std::vector<std::string>& validationMessages)
{
    if (validationMessages.empty()) return outcome;
    outcome.kind = OutcomeKind::ValidationMessages;
    outcome.messages.insert(outcome.messages.end(), validationMessages.begin(), validationMessages.end());
    return outcome;
}

} // namespace vkrt
