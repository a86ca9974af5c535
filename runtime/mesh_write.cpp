// The mesh writers: binary STL, OBJ and binary PLY, chosen by the path's extension (mesh.hpp).
#include "runtime/mesh.hpp"
#include "support/atomic_file.hpp"

#include <fmt/format.h>

#include <bit>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace frac::rt {

using u32 = std::uint32_t;
using u64 = std::uint64_t;

namespace {

// Buffered binary output, written atomically (support/atomic_file.hpp): throws naming the path; a failed
// or interrupted write leaves the previous file in place.
class OutFile {
public:
    OutFile(const std::string& path, const char* what) : file_(path, what) {}
    void bytes(const void* p, std::size_t n) {
        const auto* c = static_cast<const char*>(p);
        buf_.insert(buf_.end(), c, c + n);
        if (buf_.size() >= (1u << 20)) flush();
    }
    void text(std::string_view s) { bytes(s.data(), s.size()); }
    void u8(std::uint8_t v) { bytes(&v, 1); }
    void u16(std::uint16_t v) { le(v); }
    void u32v(u32 v) { le(v); }
    void f32(float v) { le(std::bit_cast<u32>(v)); }
    void close() {
        flush();
        file_.commit();
    }

private:
    template <typename T>
    void le(T v) { // explicit little-endian bytes, whatever the host
        unsigned char b[sizeof(T)];
        for (std::size_t i = 0; i < sizeof(T); ++i) b[i] = static_cast<unsigned char>(v >> (8 * i));
        bytes(b, sizeof(T));
    }
    void flush() {
        file_.write(buf_.data(), buf_.size());
        buf_.clear();
    }
    support::AtomicFile file_;
    std::vector<char> buf_;
};

std::string lower_extension(const std::string& path) {
    const auto slash = path.find_last_of("/\\");
    const auto dot = path.find_last_of('.');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
    std::string e = path.substr(dot);
    for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return e;
}

} // namespace

void write_stl(const Mesh& mesh, const std::string& path) {
    if (mesh.triangles.size() > std::numeric_limits<u32>::max())
        throw std::invalid_argument(fmt::format("write_stl '{}': too many triangles for STL", path));
    OutFile out(path, "STL");
    char header[80] = {};
    std::snprintf(header, sizeof header, "frac mesh: %zu triangles", mesh.triangles.size());
    out.bytes(header, sizeof header);
    out.u32v(static_cast<u32>(mesh.triangles.size()));
    for (const auto& t : mesh.triangles) {
        const auto &p = mesh.vertices[t[0]], &q = mesh.vertices[t[1]], &s = mesh.vertices[t[2]];
        const double e1[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
        const double e2[3] = {s[0] - p[0], s[1] - p[1], s[2] - p[2]};
        double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                       e1[0] * e2[1] - e1[1] * e2[0]};
        const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (double& c : n) c = len > 0 ? c / len : 0;
        for (const double c : n) out.f32(static_cast<float>(c));
        for (const u32 v : t)
            for (const double c : mesh.vertices[v]) out.f32(static_cast<float>(c));
        out.u16(0);
    }
    out.close();
}

void write_obj(const Mesh& mesh, const std::string& path) {
    OutFile out(path, "OBJ");
    fmt::memory_buffer b;
    fmt::format_to(std::back_inserter(b), "# frac mesh: {} vertices, {} triangles\n", mesh.vertices.size(),
                   mesh.triangles.size());
    for (const auto& v : mesh.vertices) {
        fmt::format_to(std::back_inserter(b), "v {} {} {}\n", v[0], v[1], v[2]);
        if (b.size() > (1u << 16)) {
            out.bytes(b.data(), b.size());
            b.clear();
        }
    }
    for (const auto& t : mesh.triangles) {
        fmt::format_to(std::back_inserter(b), "f {} {} {}\n", u64{t[0]} + 1, u64{t[1]} + 1, u64{t[2]} + 1);
        if (b.size() > (1u << 16)) {
            out.bytes(b.data(), b.size());
            b.clear();
        }
    }
    out.bytes(b.data(), b.size());
    out.close();
}

void write_ply(const Mesh& mesh, const std::string& path) {
    OutFile out(path, "PLY");
    out.text(fmt::format("ply\nformat binary_little_endian 1.0\ncomment frac mesh\nelement vertex {}\n"
                         "property float x\nproperty float y\nproperty float z\nelement face {}\n"
                         "property list uchar int vertex_indices\nend_header\n",
                         mesh.vertices.size(), mesh.triangles.size()));
    for (const auto& v : mesh.vertices)
        for (const double c : v) out.f32(static_cast<float>(c));
    for (const auto& t : mesh.triangles) {
        out.u8(3);
        for (const u32 v : t) out.u32v(v);
    }
    out.close();
}

void write_mesh(const Mesh& mesh, const std::string& path) {
    const std::string e = lower_extension(path);
    if (e == ".stl") return write_stl(mesh, path);
    if (e == ".obj") return write_obj(mesh, path);
    if (e == ".ply") return write_ply(mesh, path);
    throw std::invalid_argument(
        fmt::format("write_mesh '{}': unknown extension; use .stl, .obj or .ply", path));
}

} // namespace frac::rt
