// Large buffers backed by transparent huge pages where the kernel offers them on request
// (/sys/kernel/mm/transparent_hugepage/enabled = madvise, the default of many distributions): one page
// fault per 2 MB instead of one per 4 KB. A deep cover writes hundreds of megabytes of cells once; in a
// virtual machine each 4 KB fault costs microseconds (docs/performance.md, "Huge pages for covers").
// Only advice: where the kernel has no huge pages, or the call fails, nothing changes.
#pragma once

#include <cstddef>
#include <iterator>
#include <vector>

namespace frac::support {

// Asks for huge pages on the 2 MB-aligned part of [data, data + bytes) (memory not yet touched, such as
// a buffer just reserved, gets them at its first fault).
void advise_huge_pages(const void* data, std::size_t bytes);

// v.reserve(n) with the advice given before v's elements move into the new room (so that their copy
// faults huge pages in as well).
template <class T, class Allocator>
void reserve_huge(std::vector<T, Allocator>& v, std::size_t n) {
    if (n <= v.capacity()) return;
    std::vector<T, Allocator> room;
    room.reserve(n);
    advise_huge_pages(room.data(), room.capacity() * sizeof(T));
    room.insert(room.end(), std::make_move_iterator(v.begin()), std::make_move_iterator(v.end()));
    v.swap(room);
}

// v = n copies of `value`, in room with the advice (pictures: hundreds of megabytes written once).
template <class T>
void assign_huge(std::vector<T>& v, std::size_t n, const T& value) {
    v.clear();
    reserve_huge(v, n);
    v.assign(n, value);
}

} // namespace frac::support
