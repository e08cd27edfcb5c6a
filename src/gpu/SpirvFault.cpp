#include "gpu/SpirvFault.h"

#include "util/Error.h"

#include <bit>
#include <cmath>
#include <cstdlib>
#include <map>
#include <set>
#include <utility>

namespace vkrt {

namespace {

// ---------------------------------------------------------------- SPIR-V numbers

constexpr uint32_t kMagic = 0x07230203;
constexpr size_t kHeaderWords = 5;
constexpr size_t kBoundWord = 3;

/// The opcodes the faults read or write (SPIR-V specification, section 3.52).
namespace op {
constexpr uint32_t ExtInstImport = 11, ExtInst = 12, TypeBool = 20, TypeFloat = 22, TypeVector = 23, Constant = 43,
                   ConstantComposite = 44, Function = 54, Decorate = 71, FNegate = 127, FAdd = 129, FSub = 131,
                   FMul = 133, FDiv = 136, Select = 169, FOrdLessThan = 184, FUnordLessThan = 185,
                   FOrdGreaterThan = 186, FUnordGreaterThan = 187, FOrdLessThanEqual = 188, FUnordLessThanEqual = 189,
                   FOrdGreaterThanEqual = 190, FUnordGreaterThanEqual = 191;
} // namespace op

/// GLSL.std.450 extended instruction numbers.
namespace glsl {
constexpr uint32_t FMin = 37, FMax = 40, Fma = 50, NMin = 79, NMax = 80;
} // namespace glsl

constexpr uint32_t kNoContraction = 42; ///< SPIR-V decoration

struct ScaleClass {
    const char* name;
    uint32_t opcode;
    uint32_t extInstruction; ///< GLSL.std.450 number when opcode is OpExtInst
};

constexpr ScaleClass kScaleClasses[] = {
    {"FMul", op::FMul, 0},     {"FAdd", op::FAdd, 0},     {"FSub", op::FSub, 0},
    {"FDiv", op::FDiv, 0},     {"Sqrt", op::ExtInst, 31}, {"InverseSqrt", op::ExtInst, 32},
    {"Exp", op::ExtInst, 27},  {"Log", op::ExtInst, 28},  {"Pow", op::ExtInst, 26},
    {"Sin", op::ExtInst, 13},  {"Cos", op::ExtInst, 14},  {"Atan2", op::ExtInst, 25},
    {"Acos", op::ExtInst, 17}, {"Exp2", op::ExtInst, 29}, {"Log2", op::ExtInst, 30},
    {"Fma", op::ExtInst, 50},
};

constexpr const char* kFaultChoices = "scale:CLASS:EPS, compare:lt-le, compare:gt-ge, nan-minmax or contract";

uint32_t firstWord(uint32_t wordCount, uint32_t opcode) { return wordCount << 16 | opcode; }

// ---------------------------------------------------------------- parsing a spec

std::vector<std::string> splitAtColons(const std::string& text)
{
    std::vector<std::string> parts{""};
    for (char c : text) {
        if (c == ':') parts.emplace_back();
        else parts.back() += c;
    }
    return parts;
}

[[noreturn]] void badSpec(const std::string& spec, const std::string& problem)
{
    throw InputError("SPIR-V fault '" + spec + "': " + problem);
}

std::string scaleClassNames()
{
    std::string names;
    for (const ScaleClass& c : kScaleClasses) names += (names.empty() ? "" : ", ") + std::string(c.name);
    return names;
}

const ScaleClass& scaleClassNamed(const std::string& spec, const std::string& name)
{
    for (const ScaleClass& c : kScaleClasses)
        if (name == c.name) return c;
    badSpec(spec, "unknown instruction class '" + name + "' (valid classes: " + scaleClassNames() + ")");
}

double epsilonOf(const std::string& spec, const std::string& text)
{
    const std::string rule = " (EPS must be a finite number with |EPS| < 1, e.g. 0.01 or -1e-3)";
    char* end = nullptr;
    const double eps = text.empty() ? NAN : std::strtod(text.c_str(), &end);
    if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(eps))
        badSpec(spec, "EPS '" + text + "' is not a finite number" + rule);
    if (std::abs(eps) >= 1.0) badSpec(spec, "EPS " + text + " is out of range" + rule);
    return eps;
}

SpirvFault scaleFault(const std::string& spec, const std::vector<std::string>& parts)
{
    if (parts.size() != 3)
        badSpec(spec, "scale takes an instruction class and EPS: scale:CLASS:EPS, e.g. scale:FMul:0.01 (classes: " +
                          scaleClassNames() + ")");
    const ScaleClass& c = scaleClassNamed(spec, parts[1]);
    SpirvFault fault{SpirvFaultKind::Scale, spec};
    fault.opcode = c.opcode;
    fault.extInstruction = c.extInstruction;
    fault.epsilon = epsilonOf(spec, parts[2]);
    return fault;
}

SpirvFault compareFault(const std::string& spec, const std::vector<std::string>& parts)
{
    const std::string valid = " (valid: compare:lt-le, compare:gt-ge)";
    if (parts.size() != 2) badSpec(spec, "compare takes which comparisons to swap" + valid);
    SpirvFault fault{SpirvFaultKind::Compare, spec};
    if (parts[1] == "lt-le")
        fault.swaps = {{op::FOrdLessThan, op::FOrdLessThanEqual}, {op::FUnordLessThan, op::FUnordLessThanEqual}};
    else if (parts[1] == "gt-ge")
        fault.swaps = {{op::FOrdGreaterThan, op::FOrdGreaterThanEqual},
                       {op::FUnordGreaterThan, op::FUnordGreaterThanEqual}};
    else badSpec(spec, "unknown comparison swap '" + parts[1] + "'" + valid);
    return fault;
}

// ---------------------------------------------------------------- reading a module

/// The module's instructions after the header, each its words; InternalError
/// for a wrong magic number or a word count that is zero or runs past the end.
std::vector<std::span<const uint32_t>> instructionsOf(std::span<const uint32_t> spirv)
{
    if (spirv.size() < kHeaderWords || spirv[0] != kMagic)
        throw InternalError("SPIR-V fault injection: not a SPIR-V module (no header with magic number 0x07230203)");
    std::vector<std::span<const uint32_t>> instructions;
    for (size_t at = kHeaderWords; at < spirv.size();) {
        const uint32_t count = spirv[at] >> 16;
        if (count == 0 || count > spirv.size() - at)
            throw InternalError("SPIR-V fault injection: bad word count " + std::to_string(count) + " at word " +
                                std::to_string(at) + " of " + std::to_string(spirv.size()));
        instructions.push_back(spirv.subspan(at, count));
        at += count;
    }
    return instructions;
}

/// A literal string operand (UTF-8, nul-terminated, packed little-endian into words).
std::string literalString(std::span<const uint32_t> words)
{
    std::string text;
    for (uint32_t word : words)
        for (int byte = 0; byte < 4; ++byte) {
            const char c = char((word >> (8 * byte)) & 0xff);
            if (c == '\0') return text;
            text += c;
        }
    return text;
}

/// A float scalar or vector type.
struct FloatType {
    uint32_t width = 32;
    uint32_t components = 1;
    uint32_t scalar = 0; ///< the component type's id
};

// ---------------------------------------------------------------- rewriting

/// One pass over a module: notes the declarations the faults need, rewrites
/// the instructions the fault names, and declares new constants and types
/// just before the first function.
class FaultInjector {
public:
    FaultInjector(std::span<const uint32_t> spirv, const SpirvFault& fault)
        : m_spirv(spirv),
          m_fault(fault),
          m_bound(spirv.size() > kBoundWord ? spirv[kBoundWord] : 0)
    {
    }

    std::vector<uint32_t> run(size_t* changed)
    {
        size_t count = 0;
        for (std::span<const uint32_t> inst : instructionsOf(m_spirv)) {
            if ((inst[0] & 0xffff) == op::Function && !m_firstFunction) m_firstFunction = m_body.size();
            note(inst);
            if (rewrite(inst)) ++count;
            else m_body.insert(m_body.end(), inst.begin(), inst.end());
        }
        if (changed) *changed = count;
        return assemble();
    }

private:
    std::span<const uint32_t> m_spirv;
    const SpirvFault& m_fault;
    uint32_t m_bound;
    uint32_t m_glslSet = 0; ///< 0: GLSL.std.450 not imported
    std::map<uint32_t, FloatType> m_floatTypes;
    uint32_t m_boolType = 0;
    std::map<uint32_t, uint32_t> m_boolVectors;    ///< component count -> type id
    std::map<uint32_t, uint32_t> m_scaleConstants; ///< type id -> its 1 + EPS
    std::set<uint32_t> m_precise;                  ///< ids decorated NoContraction
    /// Contractible float multiplies seen so far: result id -> its two operands
    /// (a definition precedes its uses in a module's order, so an add's product is known).
    std::map<uint32_t, std::pair<uint32_t, uint32_t>> m_products;
    std::map<uint32_t, uint32_t> m_productTypes; ///< result id -> type id
    std::vector<uint32_t> m_declarations, m_body;
    std::optional<size_t> m_firstFunction; ///< where in m_body

    uint32_t freshId() { return m_bound++; }
    void declare(std::initializer_list<uint32_t> words) { m_declarations.insert(m_declarations.end(), words); }
    void emit(std::initializer_list<uint32_t> words) { m_body.insert(m_body.end(), words); }

    std::vector<uint32_t> assemble() const
    {
        VKRT_CHECK(m_declarations.empty() || m_firstFunction);
        std::vector<uint32_t> out(m_spirv.begin(), m_spirv.begin() + kHeaderWords);
        out[kBoundWord] = m_bound;
        const size_t split = m_firstFunction.value_or(m_body.size());
        out.insert(out.end(), m_body.begin(), m_body.begin() + ptrdiff_t(split));
        out.insert(out.end(), m_declarations.begin(), m_declarations.end());
        out.insert(out.end(), m_body.begin() + ptrdiff_t(split), m_body.end());
        return out;
    }

    /// Remembers the GLSL.std.450 import and the float and bool types.
    void note(std::span<const uint32_t> inst)
    {
        const uint32_t opcode = inst[0] & 0xffff;
        if (opcode == op::ExtInstImport && inst.size() >= 3 && literalString(inst.subspan(2)) == "GLSL.std.450")
            m_glslSet = inst[1];
        else if (opcode == op::TypeFloat && inst.size() >= 3) m_floatTypes[inst[1]] = {inst[2], 1, inst[1]};
        else if (opcode == op::TypeBool && inst.size() >= 2) m_boolType = inst[1];
        else if (opcode == op::TypeVector && inst.size() >= 4) noteVector(inst[1], inst[2], inst[3]);
        else if (opcode == op::Decorate && inst.size() >= 3 && inst[2] == kNoContraction) m_precise.insert(inst[1]);
    }

    void noteVector(uint32_t id, uint32_t component, uint32_t count)
    {
        if (auto scalar = m_floatTypes.find(component); scalar != m_floatTypes.end())
            m_floatTypes[id] = {scalar->second.width, count, component};
        else if (m_boolType != 0 && component == m_boolType) m_boolVectors[count] = id;
    }

    /// Writes `inst` changed into m_body and returns true, or returns false to have it copied.
    bool rewrite(std::span<const uint32_t> inst)
    {
        switch (m_fault.kind) {
        case SpirvFaultKind::Scale: return scale(inst);
        case SpirvFaultKind::Compare: return swapCompare(inst);
        case SpirvFaultKind::NanMinMax: return replaceMinMax(inst);
        case SpirvFaultKind::Contract: return contract(inst);
        }
        return false;
    }

    bool isGlsl(std::span<const uint32_t> inst, uint32_t instruction) const
    {
        return (inst[0] & 0xffff) == op::ExtInst && inst.size() >= 5 && inst[3] == m_glslSet && inst[4] == instruction;
    }

    // ---- scale: `T R' = original`, then `R = R' * (1 + EPS)`

    bool scale(std::span<const uint32_t> inst)
    {
        const uint32_t opcode = inst[0] & 0xffff;
        const bool matches = m_fault.opcode == op::ExtInst ? isGlsl(inst, m_fault.extInstruction)
                                                           : opcode == m_fault.opcode && inst.size() >= 3;
        if (!matches) return false;
        auto type = m_floatTypes.find(inst[1]);
        if (type == m_floatTypes.end() || type->second.width != 32) return false;
        const uint32_t result = inst[2], unscaled = freshId();
        m_body.insert(m_body.end(), inst.begin(), inst.end());
        m_body[m_body.size() - inst.size() + 2] = unscaled;
        emit({firstWord(5, op::FMul), inst[1], result, unscaled, scaleConstant(inst[1])});
        return true;
    }

    /// The constant 1 + EPS of a float32 scalar or vector type, declared once.
    uint32_t scaleConstant(uint32_t typeId)
    {
        if (auto known = m_scaleConstants.find(typeId); known != m_scaleConstants.end()) return known->second;
        const FloatType& type = m_floatTypes.at(typeId);
        const uint32_t id = freshId();
        if (type.components == 1) {
            declare({firstWord(4, op::Constant), typeId, id, std::bit_cast<uint32_t>(float(1.0 + m_fault.epsilon))});
        } else {
            const uint32_t component = scaleConstant(type.scalar);
            declare({firstWord(3 + type.components, op::ConstantComposite), typeId, id});
            m_declarations.insert(m_declarations.end(), type.components, component);
        }
        return m_scaleConstants[typeId] = id;
    }

    // ---- contract: `p = x * y; r = p + c` becomes `r = Fma(x, y, c)`; `r = p - c`
    // becomes `n = -c; r = Fma(x, y, n)`. The product stays (other uses, if any).

    bool contract(std::span<const uint32_t> inst)
    {
        const uint32_t opcode = inst[0] & 0xffff;
        if (inst.size() != 5 || m_glslSet == 0 || !m_floatTypes.count(inst[1]) || m_precise.count(inst[2]))
            return false;
        if (opcode == op::FMul) {
            m_products[inst[2]] = {inst[3], inst[4]};
            m_productTypes[inst[2]] = inst[1];
            return false;
        }
        if (opcode != op::FAdd && opcode != op::FSub) return false;
        const uint32_t type = inst[1], result = inst[2];
        const bool firstIsProduct = isProductOf(inst[3], type);
        const bool secondIsProduct = opcode == op::FAdd && isProductOf(inst[4], type);
        if (!firstIsProduct && !secondIsProduct) return false;
        const auto [x, y] = m_products.at(firstIsProduct ? inst[3] : inst[4]);
        uint32_t addend = firstIsProduct ? inst[4] : inst[3];
        if (opcode == op::FSub) {
            const uint32_t negated = freshId();
            emit({firstWord(4, op::FNegate), type, negated, addend});
            addend = negated;
        }
        emit({firstWord(8, op::ExtInst), type, result, m_glslSet, glsl::Fma, x, y, addend});
        return true;
    }

    bool isProductOf(uint32_t id, uint32_t type) const
    {
        auto product = m_productTypes.find(id);
        return product != m_productTypes.end() && product->second == type;
    }

    // ---- compare: one opcode for another

    bool swapCompare(std::span<const uint32_t> inst)
    {
        const uint32_t opcode = inst[0] & 0xffff;
        for (const auto& [a, b] : m_fault.swaps)
            if (opcode == a || opcode == b) {
                m_body.push_back((inst[0] & 0xffff0000u) | (opcode == a ? b : a));
                m_body.insert(m_body.end(), inst.begin() + 1, inst.end());
                return true;
            }
        return false;
    }

    // ---- nan-minmax: `R = min(a, b)` becomes `c = a < b; R = c ? a : b` (max: >)

    bool replaceMinMax(std::span<const uint32_t> inst)
    {
        const bool isMin = isGlsl(inst, glsl::FMin) || isGlsl(inst, glsl::NMin);
        const bool isMax = isGlsl(inst, glsl::FMax) || isGlsl(inst, glsl::NMax);
        if ((!isMin && !isMax) || inst.size() != 7 || !m_floatTypes.count(inst[1])) return false;
        const uint32_t type = inst[1], result = inst[2], a = inst[5], b = inst[6];
        const uint32_t condition = freshId();
        const uint32_t boolType = boolTypeFor(m_floatTypes.at(type).components);
        emit({firstWord(5, isMin ? op::FOrdLessThan : op::FOrdGreaterThan), boolType, condition, a, b});
        emit({firstWord(6, op::Select), type, result, condition, a, b});
        return true;
    }

    /// bool, or a vector of `components` bools: the module's own, else declared.
    uint32_t boolTypeFor(uint32_t components)
    {
        if (m_boolType == 0) {
            m_boolType = freshId();
            declare({firstWord(2, op::TypeBool), m_boolType});
        }
        if (components == 1) return m_boolType;
        if (auto known = m_boolVectors.find(components); known != m_boolVectors.end()) return known->second;
        const uint32_t id = freshId();
        declare({firstWord(4, op::TypeVector), id, m_boolType, components});
        return m_boolVectors[components] = id;
    }
};

} // namespace

SpirvFault parseSpirvFault(const std::string& spec)
{
    const std::vector<std::string> parts = splitAtColons(spec);
    if (parts[0] == "scale") return scaleFault(spec, parts);
    if (parts[0] == "compare") return compareFault(spec, parts);
    if (parts[0] == "contract") {
        if (parts.size() != 1) badSpec(spec, "contract takes no arguments");
        return SpirvFault{SpirvFaultKind::Contract, spec};
    }
    if (parts[0] == "nan-minmax") {
        if (parts.size() != 1) badSpec(spec, "nan-minmax takes no arguments");
        return SpirvFault{SpirvFaultKind::NanMinMax, spec};
    }
    badSpec(spec, "unknown fault '" + parts[0] + "' (valid: " + kFaultChoices + ")");
}

std::vector<uint32_t> injectSpirvFault(std::span<const uint32_t> spirv, const SpirvFault& fault, size_t* changed)
{
    return FaultInjector(spirv, fault).run(changed);
}

std::optional<SpirvFault> spirvFaultFromEnvironment()
{
    const char* text = std::getenv(kInjectFaultVariable);
    if (!text || !*text) return std::nullopt;
    try {
        return parseSpirvFault(text);
    } catch (const InputError& e) {
        throw InputError(std::string(kInjectFaultVariable) + ": " + e.what());
    }
}

} // namespace vkrt
