#pragma once
// Stable 64-bit FNV-1a hashing for cache keys and file fingerprints. Not
// cryptographic: it only has to make accidental collisions negligible.
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace vkrt {

class Fnv1a64 {
public:
    Fnv1a64& add(std::string_view bytes)
    {
        for (unsigned char c : bytes) {
            m_state ^= c;
            m_state *= 0x100000001b3ull;
        }
        return *this;
    }
    /// Adds a length prefix so that ("ab","c") and ("a","bc") differ.
    Fnv1a64& addField(std::string_view bytes)
    {
        add(std::to_string(bytes.size()));
        add(":");
        return add(bytes);
    }
    uint64_t value() const { return m_state; }

private:
    uint64_t m_state = 0xcbf29ce484222325ull;
};

inline uint64_t fnv1a64(std::string_view bytes) { return Fnv1a64().add(bytes).value(); }

inline std::string toHex(uint64_t value)
{
    char text[17];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(value));
    return text;
}

} // namespace vkrt
