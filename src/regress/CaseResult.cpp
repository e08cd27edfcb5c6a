#include "regress/CaseResult.h"

#include "util/Error.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <sstream>

namespace vkrt {

namespace {

using Json = nlohmann::ordered_json;

/// JSON has no infinity or NaN, but a pooled z can be infinite (a difference
/// where the variances are 0): such values travel as "inf", "-inf", "nan".
Json number(double value)
{
    if (std::isfinite(value)) return value;
    if (std::isnan(value)) return "nan";
    return value > 0 ? "inf" : "-inf";
}

double numberFrom(const Json& json)
{
    if (json.is_number()) return json.get<double>();
    const std::string text = json.get<std::string>();
    if (text == "inf") return INFINITY;
    if (text == "-inf") return -INFINITY;
    if (text == "nan") return NAN;
    throw InputError("not a number: " + text);
}

Json testToJson(const ReferenceTestResult& t)
{
    return {{"tested", t.tested},
            {"passed", t.passed},
            {"threshold", number(t.threshold)},
            {"pooledZ", number(t.pooledZ)},
            {"pooledThreshold", number(t.pooledThreshold)},
            {"minPValue", number(t.minPValue)}};
}

ReferenceTestResult testFromJson(const Json& json)
{
    ReferenceTestResult t;
    t.tested = json.at("tested").get<size_t>();
    t.passed = json.at("passed").get<size_t>();
    t.threshold = numberFrom(json.at("threshold"));
    t.pooledZ = numberFrom(json.at("pooledZ"));
    t.pooledThreshold = numberFrom(json.at("pooledThreshold"));
    t.minPValue = numberFrom(json.at("minPValue"));
    return t;
}

} // namespace

double CaseResult::duration() const
{
    double total = 0.0;
    for (const CaseAttempt& a : attempts) total += a.wallSeconds;
    return total;
}

std::string CaseResult::message() const
{
    std::ostringstream m;
    for (const CaseAttempt& a : attempts) {
        if (!m.str().empty()) m << "; ";
        if (a.number > 1) m << "re-run ";
        m << "seed " << a.seed << ": " << statusName(a.status);
        if (!a.problem.empty()) m << " (" << a.problem << ")";
        if (!a.note.empty()) m << " [" << a.note << "]";
    }
    return attempts.size() == 1 && attempts.front().status == CaseStatus::Pass && attempts.front().note.empty()
               ? std::string()
               : m.str();
}

std::string attemptToJson(const CaseAttempt& a)
{
    Json json{{"attempt", a.number},
              {"seed", a.seed},
              {"status", statusName(a.status)},
              {"problem", a.problem},
              {"note", a.note},
              {"slow", a.slow},
              {"test", testToJson(a.test)},
              {"relMse", number(a.relMse)},
              {"rejectedSamples", a.rejectedSamples},
              {"seconds", number(a.seconds)},
              {"wroteImages", a.wroteImages},
              {"device", a.device},
              {"driver", a.driver}};
    // Invalid UTF-8 (in an error message quoting a path) is replaced, not thrown on.
    return json.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

CaseAttempt attemptFromJson(const std::string& text)
{
    try {
        const Json json = Json::parse(text);
        CaseAttempt a;
        a.number = json.at("attempt").get<int>();
        a.seed = json.at("seed").get<uint32_t>();
        std::optional<CaseStatus> status = statusNamed(json.at("status").get<std::string>());
        if (!status || !(isFailure(*status) || *status == CaseStatus::Pass))
            throw InputError("status " + json.at("status").dump() + " is not an attempt's");
        a.status = *status;
        a.problem = json.at("problem").get<std::string>();
        a.note = json.at("note").get<std::string>();
        a.slow = json.at("slow").get<bool>();
        a.test = testFromJson(json.at("test"));
        a.relMse = numberFrom(json.at("relMse"));
        a.rejectedSamples = json.at("rejectedSamples").get<uint64_t>();
        a.seconds = numberFrom(json.at("seconds"));
        a.wroteImages = json.at("wroteImages").get<bool>();
        a.device = json.at("device").get<std::string>();
        a.driver = json.at("driver").get<std::string>();
        return a;
    } catch (const nlohmann::json::exception& e) {
        throw InputError(std::string("not a case result: ") + e.what());
    }
}

} // namespace vkrt
