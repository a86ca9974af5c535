// An allocator for buffers sized first and filled afterwards, out of order, by several threads: its
// vector's resize() leaves the new elements unwritten instead of zeroing them. Zeroing would be a
// serial pass over memory the threads then write again, and it would take every page fault on the
// thread that resizes (a depth-12 carpet cover keeps 200 MB of cells).
#pragma once

#include <memory>
#include <type_traits>
#include <utility>

namespace frac::support {

template <class T>
struct FillLater : std::allocator<T> {
    // Left unwritten, an element is still an object: implicit-lifetime types only (trivial ones).
    static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);

    template <class U>
    struct rebind {
        using other = FillLater<U>;
    };

    FillLater() = default;
    template <class U>
    FillLater(const FillLater<U>&) noexcept {}

    // Value-initialization (resize, emplace_back()): left for the caller to write.
    template <class U>
    void construct(U*) noexcept {}
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};

template <class T, class U>
bool operator==(const FillLater<T>&, const FillLater<U>&) noexcept {
    return true;
}

} // namespace frac::support
