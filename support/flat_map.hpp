// A map from small keys (pointers to nodes of a tree, node numbers of a graph) to small values, for the
// passes that annotate every node: open addressing in one array, so an entry costs no allocation of
// its own and a lookup reads one cache line, where std::unordered_map allocates a node per entry.
// `empty` is a key never stored (null, no_node): it marks a free slot.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

namespace frac::support {

template <class Key, class Value, Key empty = Key{}>
class FlatMap {
    static_assert(std::is_pointer_v<Key> || std::is_integral_v<Key>, "FlatMap keys are pointers or integers");

public:
    std::size_t size() const { return size_; }
    std::size_t count(Key key) const { return find(key) ? 1 : 0; }

    // The value of `key`, or null.
    const Value* find(Key key) const {
        if (slots_.empty() || key == empty) return nullptr;
        for (std::size_t at = home(key);; at = next(at)) {
            if (slots_[at].first == key) return &slots_[at].second;
            if (slots_[at].first == empty) return nullptr;
        }
    }
    const Value& at(Key key) const {
        if (const Value* v = find(key)) return *v;
        throw std::out_of_range("FlatMap::at: no such key");
    }

    // The value of `key`, value-initialised when new. `key` is not `empty`.
    Value& operator[](Key key) {
        if (2 * (size_ + 1) > slots_.size()) grow();
        std::size_t at = home(key);
        for (; slots_[at].first != empty; at = next(at))
            if (slots_[at].first == key) return slots_[at].second;
        ++size_;
        slots_[at] = {key, Value{}};
        return slots_[at].second;
    }

private:
    std::size_t home(Key key) const {
        // Fibonacci hashing: the high bits of the product spread aligned addresses and consecutive
        // numbers over the table.
        std::uint64_t bits;
        if constexpr (std::is_pointer_v<Key>)
            bits = static_cast<std::uint64_t>(reinterpret_cast<std::uintptr_t>(key));
        else
            bits = static_cast<std::uint64_t>(key);
        return static_cast<std::size_t>((bits * 0x9e3779b97f4a7c15ULL) >> shift_);
    }
    std::size_t next(std::size_t at) const { return (at + 1) & (slots_.size() - 1); }

    void grow() {
        std::vector<std::pair<Key, Value>> old = std::move(slots_);
        slots_.assign(old.empty() ? 64 : 2 * old.size(), {empty, Value{}});
        shift_ = 64 - std::countr_zero(slots_.size());
        for (auto& [key, value] : old) {
            if (key == empty) continue;
            std::size_t at = home(key);
            while (slots_[at].first != empty) at = next(at);
            slots_[at] = {key, std::move(value)};
        }
    }

    std::vector<std::pair<Key, Value>> slots_; // a power of two in size, at most half full
    std::size_t size_ = 0;
    int shift_ = 64;
};

} // namespace frac::support
