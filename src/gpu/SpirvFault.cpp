#include "gpu/SpirvFault.h"

#include "util/Error.h"

#include <bit>
#include <cctype>
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
constexpr uint32_t EntryPoint = 15, Store = 62, LogicalOr = 166, LogicalAnd = 167, LogicalNot = 168, UGreaterThan = 172,
                   LoopMerge = 246, Branch = 249, BranchConditional = 250;
constexpr uint32_t ExtInstImport = 11, ExtInst = 12, TypeVoid = 19, TypeBool = 20, TypeInt = 21, TypeFloat = 22,
                   TypeVector = 23, TypeRuntimeArray = 29, TypeStruct = 30, TypePointer = 32, TypeForwardPointer = 39,
                   Constant = 43, ConstantComposite = 44, Function = 54, Variable = 59, Load = 61, AccessChain = 65,
                   InBoundsAccessChain = 66, Decorate = 71, CompositeConstruct = 80, CompositeExtract = 81,
                   ImageFetch = 95, Bitcast = 124, FNegate = 127, IAdd = 128, FAdd = 129, FSub = 131, IMul = 132,
                   FMul = 133, FDiv = 136, UMod = 137, VectorTimesScalar = 142, Select = 169, IEqual = 170,
                   FOrdLessThan = 184, FUnordLessThan = 185, FOrdGreaterThan = 186, FUnordGreaterThan = 187,
                   FOrdLessThanEqual = 188, FUnordLessThanEqual = 189, FOrdGreaterThanEqual = 190,
                   FUnordGreaterThanEqual = 191, ShiftRightLogical = 194, BitwiseXor = 198,
                   RayQueryGetIntersectionT = 6018;
} // namespace op

constexpr uint32_t kStorageBufferClass = 12, kPrivateClass = 6; ///< SPIR-V storage classes

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
    {"FMul", op::FMul, 0},
    {"FAdd", op::FAdd, 0},
    {"FSub", op::FSub, 0},
    {"FDiv", op::FDiv, 0},
    {"Sqrt", op::ExtInst, 31},
    {"InverseSqrt", op::ExtInst, 32},
    {"Exp", op::ExtInst, 27},
    {"Log", op::ExtInst, 28},
    {"Pow", op::ExtInst, 26},
    {"Sin", op::ExtInst, 13},
    {"Cos", op::ExtInst, 14},
    {"Atan2", op::ExtInst, 25},
    {"Acos", op::ExtInst, 17},
    {"Exp2", op::ExtInst, 29},
    {"Log2", op::ExtInst, 30},
    {"Fma", op::ExtInst, 50},
    {"RayQueryT", op::RayQueryGetIntersectionT, 0},
};

constexpr const char* kFaultChoices = "scale:CLASS:EPS[:1inN], compare:lt-le, compare:gt-ge, nan-minmax, "
                                      "neighbour-load[:1inN], texel-offset[:1inN], loop-cut:N or contract";

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
    // strtod skips leading white space: 'scale:FMul: 0.1' must be refused as written, not read as 0.1.
    const bool spaced = !text.empty() && std::isspace(static_cast<unsigned char>(text.front()));
    const double eps = text.empty() ? NAN : std::strtod(text.c_str(), &end);
    if (text.empty() || spaced || end != text.c_str() + text.size() || !std::isfinite(eps))
        badSpec(spec, "EPS '" + text + "' is not a finite number" + rule);
    if (std::abs(eps) >= 1.0) badSpec(spec, "EPS " + text + " is out of range" + rule);
    return eps;
}

/// A whole number from 1 to 2^31 written in `digits`, or nullopt (and
/// `outOfRange` set when it is a number, but too small or too large).
std::optional<uint32_t> countOf(const std::string& digits, bool& outOfRange)
{
    outOfRange = false;
    if (digits.empty() || digits.size() > 10 || digits.find_first_not_of("0123456789") != std::string::npos)
        return std::nullopt;
    const unsigned long long n = std::stoull(digits);
    outOfRange = n < 1 || n > (1ull << 31);
    if (outOfRange) return std::nullopt;
    return uint32_t(n);
}

/// N of a "1inN" part.
uint32_t oneInOf(const std::string& spec, const std::string& text)
{
    const std::string rule = " (write 1inN with N a whole number from 1 to 2147483648, e.g. 1in1000)";
    bool outOfRange = false;
    const std::optional<uint32_t> n = text.rfind("1in", 0) == 0 ? countOf(text.substr(3), outOfRange) : std::nullopt;
    if (outOfRange) badSpec(spec, "N in '" + text + "' is out of range" + rule);
    if (!n) badSpec(spec, "'" + text + "' is not 1inN" + rule);
    return *n;
}

SpirvFault scaleFault(const std::string& spec, const std::vector<std::string>& parts)
{
    if (parts.size() != 3 && parts.size() != 4)
        badSpec(spec, "scale takes an instruction class, EPS and optionally 1inN: scale:CLASS:EPS[:1inN], e.g. "
                      "scale:FMul:0.01 or scale:FMul:0.5:1in1000 (classes: " +
                          scaleClassNames() + ")");
    const ScaleClass& c = scaleClassNamed(spec, parts[1]);
    SpirvFault fault{SpirvFaultKind::Scale, spec};
    fault.opcode = c.opcode;
    fault.extInstruction = c.extInstruction;
    fault.epsilon = epsilonOf(spec, parts[2]);
    if (parts.size() == 4) fault.oneIn = oneInOf(spec, parts[3]);
    return fault;
}

SpirvFault loopCutFault(const std::string& spec, const std::vector<std::string>& parts)
{
    const std::string rule = " (loop-cut:N, N a whole number of loop passes from 1 to 2147483648, e.g. loop-cut:65535)";
    if (parts.size() != 2) badSpec(spec, "loop-cut takes the number of passes" + rule);
    SpirvFault fault{SpirvFaultKind::LoopCut, spec};
    bool outOfRange = false;
    const std::optional<uint32_t> passes = countOf(parts[1], outOfRange);
    if (outOfRange) badSpec(spec, "N in '" + parts[1] + "' is out of range" + rule);
    if (!passes) badSpec(spec, "'" + parts[1] + "' is not a number of passes" + rule);
    fault.loopPasses = *passes;
    return fault;
}

/// neighbour-load[:1inN] and texel-offset[:1inN].
SpirvFault offsetFault(const std::string& spec, const std::vector<std::string>& parts, SpirvFaultKind kind)
{
    if (parts.size() > 2)
        badSpec(spec, parts[0] + " takes at most 1inN: " + parts[0] + "[:1inN], e.g. " + parts[0] + ":1in100");
    SpirvFault fault{kind, spec};
    if (parts.size() == 2) fault.oneIn = oneInOf(spec, parts[1]);
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

/// An integer scalar or vector type.
struct IntType {
    uint32_t width = 32;
    bool isSigned = false;
    uint32_t components = 1;
    uint32_t scalar = 0; ///< the component type's id
};

bool declaresType(uint32_t opcode)
{
    return (opcode >= op::TypeVoid && opcode < op::TypeForwardPointer) || opcode == 4472 /* RayQueryKHR */ ||
           opcode == 5341 /* AccelerationStructureKHR */;
}

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
            if ((inst[0] & 0xffff) == op::EntryPoint) m_entryPointAt = m_body.size();
            note(inst);
            if (rewrite(inst)) count += !std::exchange(m_heldBack, false);
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
    uint32_t m_floatOne = 0;                       ///< the float32 1.0 declared here
    std::map<uint32_t, IntType> m_intTypes;
    uint32_t m_uintType = 0;                                          ///< 32-bit unsigned; 0 until known
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> m_intConstants; ///< (type, value) -> id, declared here
    std::map<uint32_t, uint32_t> m_constantValues;                    ///< the module's 32-bit scalar constants
    std::set<uint32_t> m_typeIds;
    std::map<uint32_t, uint32_t> m_resultTypes;                   ///< value id -> type id
    std::map<uint32_t, std::pair<uint32_t, uint32_t>> m_pointers; ///< type id -> (storage class, pointee)
    std::map<uint32_t, std::vector<uint32_t>> m_structs;          ///< type id -> member types
    std::set<uint32_t> m_runtimeArrays;
    /// Access chains into a storage buffer's runtime array (words as written),
    /// and chains that go on from one of those.
    std::map<uint32_t, std::vector<uint32_t>> m_elementChains;
    /// loop-cut: the Private counter of loop-header entries (0 until made),
    /// and a header's OpLoopMerge held back until its branch is seen.
    uint32_t m_passCounter = 0;
    std::vector<uint32_t> m_heldLoopMerge;
    bool m_heldBack = false;      ///< rewrite() kept the instruction to write later: not a change by itself
    size_t m_entryPointAt = 0;    ///< where in m_body the OpEntryPoint is (its interface gains the counter)
    std::set<uint32_t> m_precise; ///< ids decorated NoContraction
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
        std::vector<uint32_t> declarations(m_body.begin(), m_body.begin() + ptrdiff_t(split));
        if (m_passCounter != 0) { // SPIR-V 1.4 on: an entry point lists every global it uses
            const uint32_t count = declarations.at(m_entryPointAt) >> 16;
            declarations.insert(declarations.begin() + ptrdiff_t(m_entryPointAt + count), m_passCounter);
            declarations[m_entryPointAt] += 1u << 16;
        }
        out.insert(out.end(), declarations.begin(), declarations.end());
        out.insert(out.end(), m_declarations.begin(), m_declarations.end());
        out.insert(out.end(), m_body.begin() + ptrdiff_t(split), m_body.end());
        return out;
    }

    /// Remembers the GLSL.std.450 import, the types, constants, variables,
    /// and the type of each value a function computes.
    void note(std::span<const uint32_t> inst)
    {
        const uint32_t opcode = inst[0] & 0xffff;
        if (declaresType(opcode) && inst.size() >= 2) m_typeIds.insert(inst[1]);
        if (opcode == op::ExtInstImport && inst.size() >= 3 && literalString(inst.subspan(2)) == "GLSL.std.450")
            m_glslSet = inst[1];
        else if (opcode == op::TypeFloat && inst.size() >= 3) m_floatTypes[inst[1]] = {inst[2], 1, inst[1]};
        else if (opcode == op::TypeInt && inst.size() >= 4) noteInt(inst[1], inst[2], inst[3] != 0);
        else if (opcode == op::TypeBool && inst.size() >= 2) m_boolType = inst[1];
        else if (opcode == op::TypeVector && inst.size() >= 4) noteVector(inst[1], inst[2], inst[3]);
        else if (opcode == op::TypePointer && inst.size() >= 4) m_pointers[inst[1]] = {inst[2], inst[3]};
        else if (opcode == op::TypeStruct && inst.size() >= 2) m_structs[inst[1]].assign(inst.begin() + 2, inst.end());
        else if (opcode == op::TypeRuntimeArray && inst.size() >= 3) m_runtimeArrays.insert(inst[1]);
        else if (opcode == op::Decorate && inst.size() >= 3 && inst[2] == kNoContraction) m_precise.insert(inst[1]);
        else if (opcode == op::Constant && inst.size() == 4) m_constantValues[inst[2]] = inst[3];
        // Declarations before the functions put other ids in word 1 (names,
        // decorations); in a function, an instruction whose word 1 is a type
        // has that type and its result in word 2.
        const bool typed =
            m_firstFunction || opcode == op::Constant || opcode == op::ConstantComposite || opcode == op::Variable;
        if (typed && inst.size() >= 3 && m_typeIds.count(inst[1])) m_resultTypes[inst[2]] = inst[1];
    }

    void noteInt(uint32_t id, uint32_t width, bool isSigned)
    {
        m_intTypes[id] = {width, isSigned, 1, id};
        if (width == 32 && !isSigned && m_uintType == 0) m_uintType = id;
    }

    void noteVector(uint32_t id, uint32_t component, uint32_t count)
    {
        if (auto scalar = m_floatTypes.find(component); scalar != m_floatTypes.end())
            m_floatTypes[id] = {scalar->second.width, count, component};
        else if (auto integer = m_intTypes.find(component); integer != m_intTypes.end())
            m_intTypes[id] = {integer->second.width, integer->second.isSigned, count, component};
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
        case SpirvFaultKind::NeighbourLoad: return loadNeighbour(inst);
        case SpirvFaultKind::TexelOffset: return offsetTexelFetch(inst);
        case SpirvFaultKind::LoopCut: return cutLoop(inst);
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
        auto found = m_floatTypes.find(inst[1]);
        if (found == m_floatTypes.end() || found->second.width != 32) return false;
        const uint32_t result = inst[2], unscaled = freshId();
        m_body.insert(m_body.end(), inst.begin(), inst.end());
        m_body[m_body.size() - inst.size() + 2] = unscaled;
        if (m_fault.oneIn == 1) {
            emit({firstWord(5, op::FMul), inst[1], result, unscaled, scaleConstant(inst[1])});
            return true;
        }
        // 1 in N: the factor is 1 + EPS where the first component's bits are selected, else 1.
        const FloatType type = found->second;
        uint32_t first = unscaled;
        if (type.components > 1) {
            first = freshId();
            emit({firstWord(5, op::CompositeExtract), type.scalar, first, unscaled, 0});
        }
        const uint32_t bits = freshId(), factor = freshId();
        emit({firstWord(4, op::Bitcast), uintType(), bits, first});
        emit({firstWord(6, op::Select), type.scalar, factor, selects(bits), scaleConstant(type.scalar),
              floatOne(type.scalar)});
        if (type.components == 1) emit({firstWord(5, op::FMul), inst[1], result, unscaled, factor});
        else emit({firstWord(5, op::VectorTimesScalar), inst[1], result, unscaled, factor});
        return true;
    }

    uint32_t floatOne(uint32_t scalarType)
    {
        if (m_floatOne == 0) {
            m_floatOne = freshId();
            declare({firstWord(4, op::Constant), scalarType, m_floatOne, std::bit_cast<uint32_t>(1.0f)});
        }
        return m_floatOne;
    }

    // ---- 1 in N: a bool that is true where spirvFaultSelects(key, N)

    uint32_t uintType()
    {
        if (m_uintType == 0) {
            m_uintType = freshId();
            declare({firstWord(4, op::TypeInt), m_uintType, 32, 0});
            m_intTypes[m_uintType] = {32, false, 1, m_uintType};
        }
        return m_uintType;
    }

    /// A 32-bit integer constant of `type` (scalar), declared once.
    uint32_t intConstant(uint32_t type, uint32_t value)
    {
        auto [slot, isNew] = m_intConstants.try_emplace({type, value}, 0);
        if (isNew) {
            slot->second = freshId();
            declare({firstWord(4, op::Constant), type, slot->second, value});
        }
        return slot->second;
    }

    /// Emits spirvFaultSelects(key, N) for a uint `key`; returns the bool's id.
    uint32_t selects(uint32_t key)
    {
        const uint32_t u = uintType();
        uint32_t h = key;
        for (uint32_t multiplier : {0x9E3779B1u, 0x85EBCA6Bu}) {
            const uint32_t product = freshId(), shifted = freshId(), mixed = freshId();
            const uint32_t shift = multiplier == 0x9E3779B1u ? 16 : 13;
            emit({firstWord(5, op::IMul), u, product, h, intConstant(u, multiplier)});
            emit({firstWord(5, op::ShiftRightLogical), u, shifted, product, intConstant(u, shift)});
            emit({firstWord(5, op::BitwiseXor), u, mixed, product, shifted});
            h = mixed;
        }
        const uint32_t remainder = freshId(), selected = freshId();
        emit({firstWord(5, op::UMod), u, remainder, h, intConstant(u, m_fault.oneIn)});
        emit({firstWord(5, op::IEqual), boolTypeFor(1), selected, remainder, intConstant(u, 0)});
        return selected;
    }

    /// `value` (a 32-bit integer scalar) as a uint, for selects().
    uint32_t asUint(uint32_t value)
    {
        if (m_resultTypes.at(value) == uintType()) return value;
        const uint32_t bits = freshId();
        emit({firstWord(4, op::Bitcast), uintType(), bits, value});
        return bits;
    }

    /// `index + 1`, or `index + (selected ? 1 : 0)` for 1 in N: `index` a 32-bit integer scalar.
    uint32_t nextIndex(uint32_t index, uint32_t key)
    {
        const uint32_t type = m_resultTypes.at(index), one = intConstant(type, 1);
        uint32_t step = one;
        if (m_fault.oneIn != 1) {
            step = freshId();
            emit({firstWord(6, op::Select), type, step, selects(key), one, intConstant(type, 0)});
        }
        const uint32_t next = freshId();
        emit({firstWord(5, op::IAdd), type, next, index, step});
        return next;
    }

    bool isInt32Scalar(uint32_t value) const
    {
        auto type = m_resultTypes.find(value);
        if (type == m_resultTypes.end()) return false;
        auto integer = m_intTypes.find(type->second);
        return integer != m_intTypes.end() && integer->second.width == 32 && integer->second.components == 1;
    }

    // ---- loop-cut: each loop header counts its entries in a Private
    // counter shared by all loops; once past N, the header leaves the loop.

    bool cutLoop(std::span<const uint32_t> inst)
    {
        const uint32_t opcode = inst[0] & 0xffff;
        if (opcode == op::LoopMerge && inst.size() >= 4) {
            m_heldLoopMerge.assign(inst.begin(), inst.end());
            m_heldBack = true;
            return true; // written with its branch
        }
        if (m_heldLoopMerge.empty()) return false;
        const std::vector<uint32_t> loopMerge = std::exchange(m_heldLoopMerge, {});
        const uint32_t merge = loopMerge[1];
        const bool isBranch = opcode == op::Branch && inst.size() == 2;
        const bool isConditional =
            opcode == op::BranchConditional && inst.size() >= 4 && (inst[2] == merge || inst[3] == merge);
        if (!isBranch && !isConditional) { // a header that does not branch to its merge block: left alone
            m_body.insert(m_body.end(), loopMerge.begin(), loopMerge.end());
            return false;
        }
        const uint32_t over = emitPassCount();
        if (isBranch) {
            m_body.insert(m_body.end(), loopMerge.begin(), loopMerge.end());
            emit({firstWord(4, op::BranchConditional), over, merge, inst[1]});
            return true;
        }
        // Leave when the loop would, or when over: c || over if true leaves, c && !over if false does.
        const uint32_t condition = freshId();
        if (inst[2] == merge) {
            emit({firstWord(5, op::LogicalOr), boolTypeFor(1), condition, inst[1], over});
        } else {
            const uint32_t stay = freshId();
            emit({firstWord(4, op::LogicalNot), boolTypeFor(1), stay, over});
            emit({firstWord(5, op::LogicalAnd), boolTypeFor(1), condition, inst[1], stay});
        }
        m_body.insert(m_body.end(), loopMerge.begin(), loopMerge.end());
        std::vector<uint32_t> branch(inst.begin(), inst.end());
        branch[1] = condition;
        m_body.insert(m_body.end(), branch.begin(), branch.end());
        return true;
    }

    /// counter += 1; returns the bool counter > N.
    uint32_t emitPassCount()
    {
        const uint32_t u = uintType();
        if (m_passCounter == 0) {
            uint32_t pointer = 0;
            for (const auto& [id, target] : m_pointers)
                if (target == std::pair<uint32_t, uint32_t>{kPrivateClass, u}) pointer = id;
            if (pointer == 0) {
                pointer = freshId();
                declare({firstWord(4, op::TypePointer), pointer, kPrivateClass, u});
                m_pointers[pointer] = {kPrivateClass, u};
            }
            m_passCounter = freshId();
            declare({firstWord(5, op::Variable), pointer, m_passCounter, kPrivateClass, intConstant(u, 0)});
        }
        const uint32_t before = freshId(), after = freshId(), over = freshId();
        emit({firstWord(4, op::Load), u, before, m_passCounter});
        emit({firstWord(5, op::IAdd), u, after, before, intConstant(u, 1)});
        emit({firstWord(3, op::Store), m_passCounter, after});
        emit({firstWord(5, op::UGreaterThan), boolTypeFor(1), over, after, intConstant(u, m_fault.loopPasses)});
        return over;
    }

    // ---- neighbour-load: `p = &buffer.array[i]...; x = *p` becomes `x = *&buffer.array[i + 1]...`

    bool loadNeighbour(std::span<const uint32_t> inst)
    {
        const uint32_t opcode = inst[0] & 0xffff;
        if ((opcode == op::AccessChain || opcode == op::InBoundsAccessChain) && inst.size() >= 5) {
            if (m_elementChains.count(inst[3]) || isArrayElement(inst))
                m_elementChains[inst[2]].assign(inst.begin(), inst.end());
            return false;
        }
        if (opcode != op::Load || inst.size() < 4 || !m_elementChains.count(inst[3])) return false;
        const uint32_t pointer = neighbourChain(inst[3]);
        if (pointer == 0) return false;
        m_body.insert(m_body.end(), inst.begin(), inst.end());
        m_body[m_body.size() - inst.size() + 3] = pointer;
        return true;
    }

    /// An access chain from a storage-buffer variable through a runtime-array
    /// member to an element whose index is computed (not a constant).
    bool isArrayElement(std::span<const uint32_t> chain) const
    {
        if (chain.size() < 6) return false;
        auto base = m_resultTypes.find(chain[3]);
        if (base == m_resultTypes.end()) return false;
        auto pointer = m_pointers.find(base->second);
        if (pointer == m_pointers.end() || pointer->second.first != kStorageBufferClass) return false;
        auto members = m_structs.find(pointer->second.second);
        auto member = m_constantValues.find(chain[4]);
        if (members == m_structs.end() || member == m_constantValues.end() || member->second >= members->second.size())
            return false;
        return m_runtimeArrays.count(members->second[member->second]) && !m_constantValues.count(chain[5]) &&
               isInt32Scalar(chain[5]);
    }

    /// A copy of chain `id` that reaches the next element (emitted here); 0 if it cannot.
    uint32_t neighbourChain(uint32_t id)
    {
        std::vector<uint32_t> words = m_elementChains.at(id);
        if (m_elementChains.count(words[3])) {
            words[3] = neighbourChain(words[3]);
            if (words[3] == 0) return 0;
        } else {
            words[5] = nextIndex(words[5], asUint(words[5]));
        }
        words[2] = freshId();
        m_body.insert(m_body.end(), words.begin(), words.end());
        return words[2];
    }

    // ---- texel-offset: texelFetch(image, (x, y)) reads (x + 1, y)

    bool offsetTexelFetch(std::span<const uint32_t> inst)
    {
        if ((inst[0] & 0xffff) != op::ImageFetch || inst.size() < 5) return false;
        auto coordinateType = m_resultTypes.find(inst[4]);
        if (coordinateType == m_resultTypes.end()) return false;
        auto type = m_intTypes.find(coordinateType->second);
        if (type == m_intTypes.end() || type->second.width != 32 || type->second.components < 2) return false;
        const uint32_t coordinate = inst[4], vector = coordinateType->second, scalar = type->second.scalar;
        const uint32_t x = freshId(), y = freshId();
        emit({firstWord(5, op::CompositeExtract), scalar, x, coordinate, 0});
        emit({firstWord(5, op::CompositeExtract), scalar, y, coordinate, 1});
        m_resultTypes[x] = m_resultTypes[y] = scalar;
        // The key x + 65536 y picks texels, not values: the same texel is wrong for every ray.
        const uint32_t yHigh = freshId(), key = freshId();
        emit({firstWord(5, op::IMul), uintType(), yHigh, asUint(y), intConstant(uintType(), 65536)});
        emit({firstWord(5, op::IAdd), uintType(), key, asUint(x), yHigh});
        const uint32_t nextX = nextIndex(x, key), shifted = freshId();
        std::vector<uint32_t> construct{firstWord(3 + type->second.components, op::CompositeConstruct), vector, shifted,
                                        nextX, y};
        for (uint32_t k = 2; k < type->second.components; ++k) {
            const uint32_t component = freshId();
            emit({firstWord(5, op::CompositeExtract), scalar, component, coordinate, k});
            construct.push_back(component);
        }
        m_body.insert(m_body.end(), construct.begin(), construct.end());
        m_body.insert(m_body.end(), inst.begin(), inst.end());
        m_body[m_body.size() - inst.size() + 4] = shifted;
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
    if (parts[0] == "neighbour-load") return offsetFault(spec, parts, SpirvFaultKind::NeighbourLoad);
    if (parts[0] == "texel-offset") return offsetFault(spec, parts, SpirvFaultKind::TexelOffset);
    if (parts[0] == "loop-cut") return loopCutFault(spec, parts);
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
