#include "regress/CaseStatus.h"

#include <array>
#include <utility>

namespace vkrt {

namespace {

constexpr std::array<std::pair<CaseStatus, const char*>, 9> kNames{{
    {CaseStatus::Pass, "Pass"},
    {CaseStatus::Fail, "Fail"},
    {CaseStatus::Crash, "Crash"},
    {CaseStatus::Timeout, "Timeout"},
    {CaseStatus::Flake, "Flake"},
    {CaseStatus::Skip, "Skip"},
    {CaseStatus::ExpectedFail, "ExpectedFail"},
    {CaseStatus::UnexpectedPass, "UnexpectedPass"},
    {CaseStatus::KnownFlake, "KnownFlake"},
}};

} // namespace

std::string statusName(CaseStatus status)
{
    for (const auto& [value, name] : kNames)
        if (value == status) return name;
    return "Unknown";
}

std::optional<CaseStatus> statusNamed(const std::string& name)
{
    for (const auto& [value, spelling] : kNames)
        if (name == spelling) return value;
    return std::nullopt;
}

bool isFailure(CaseStatus status)
{
    return status == CaseStatus::Fail || status == CaseStatus::Crash || status == CaseStatus::Timeout;
}

bool failsTheRun(CaseStatus status) { return isFailure(status) || status == CaseStatus::UnexpectedPass; }

} // namespace vkrt
