// fnv1a.h — the 64-bit FNV-1a hash (Fowler, Noll, Vo), for identities and cache keys that must
// be the same on every run and machine (a render's scene fingerprint, a specialised kernel's
// cache file); not for security. Its start value is not the published offset basis
// (14695981039346656037: one digit fewer); the scene fingerprints that checkpoints record were
// made with it, so it stays.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace gdpt {

class Fnv1a {
public:
    void bytes(const void* data, std::size_t n) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (std::size_t i = 0; i < n; ++i) hash_ = (hash_ ^ p[i]) * 1099511628211ull;
    }
    template <typename T>
    void vector(const std::vector<T>& v) {
        const std::uint64_t n = v.size();
        bytes(&n, sizeof n);  // so that moving an element between arrays changes the hash
        if (!v.empty()) bytes(v.data(), v.size() * sizeof(T));
    }
    template <typename T>
    void value(const T& v) {
        bytes(&v, sizeof v);
    }
    void text(const std::string& s) { bytes(s.data(), s.size()); }
    [[nodiscard]] std::uint64_t hash() const { return hash_; }

private:
    std::uint64_t hash_ = 1469598103934665603ull;
};

// 16 lowercase hex digits.
inline std::string hex(std::uint64_t v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
    return buf;
}

}  // namespace gdpt
