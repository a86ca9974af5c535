#include "runtime/automata/distance_function.hpp"

#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>
#include <utility>

namespace frac::rt {

AttractorDistanceFunction::AttractorDistanceFunction(AttractorDistance distance, std::string automaton_name)
    : distance_(std::move(distance)), name_(std::move(automaton_name)) {}

DistanceOptions AttractorDistanceFunction::default_options() {
    DistanceOptions o;
    o.epsilon = 1e-6;
    return o;
}

num::Interval AttractorDistanceFunction::eval_box(const num::Interval* args) const {
    const int d = distance_.dimension();
    for (int k = 0; k < d; ++k)
        if (args[k].is_empty()) return num::Interval::empty();
    for (int k = 0; k < d; ++k)
        if (!std::isfinite(args[k].lo) || !std::isfinite(args[k].hi))
            return {0.0, std::numeric_limits<double>::infinity()}; // a distance, unbounded box
    return distance_.eval_box(args);
}

double AttractorDistanceFunction::eval_point(const double* args) const {
    const int d = distance_.dimension();
    for (int k = 0; k < d; ++k) {
        if (std::isnan(args[k])) return std::numeric_limits<double>::quiet_NaN();
        if (std::isinf(args[k])) return std::numeric_limits<double>::infinity();
    }
    const num::Interval r = distance_.eval_point(args);
    return num::midpoint(r);
}

// The data: the automaton's name (its length, then its bytes), then the distance's own serialization.
std::optional<ir::ExternalFunction::Compiled> AttractorDistanceFunction::compiled() const {
    Compiled c{
        "libfrac_aot_automata.a", "frac_aot_attractor_distance", "frac_aot_attractor_distance_release", {}};
    const std::uint64_t length = name_.size();
    const std::vector<std::uint8_t> distance = distance_.serialize();
    c.data.resize(sizeof length + name_.size() + distance.size());
    std::memcpy(c.data.data(), &length, sizeof length);
    std::memcpy(c.data.data() + sizeof length, name_.data(), name_.size());
    std::memcpy(c.data.data() + sizeof length + name_.size(), distance.data(), distance.size());
    return c;
}

AttractorDistanceFunction AttractorDistanceFunction::from_compiled(const std::uint8_t* data,
                                                                   std::size_t size) {
    std::uint64_t length = 0;
    if (size < sizeof length) throw std::invalid_argument("malformed attractor distance data");
    std::memcpy(&length, data, sizeof length);
    if (length > size - sizeof length) throw std::invalid_argument("malformed attractor distance data");
    const std::size_t skip = sizeof length + static_cast<std::size_t>(length);
    return {
        AttractorDistance::deserialize(data + skip, size - skip),
        std::string(reinterpret_cast<const char*>(data + sizeof length), static_cast<std::size_t>(length))};
}

} // namespace frac::rt

extern "C" {

const frac::ir::ExternalFunction* frac_aot_attractor_distance(frac::ir::ExternalData* record) noexcept {
    std::atomic_ref<const frac::ir::ExternalFunction*> slot(record->function);
    if (const frac::ir::ExternalFunction* f = slot.load(std::memory_order_acquire)) return f;
    try {
        auto fresh = std::make_unique<frac::rt::AttractorDistanceFunction>(
            frac::rt::AttractorDistanceFunction::from_compiled(record->data, record->size));
        const frac::ir::ExternalFunction* published = nullptr;
        if (slot.compare_exchange_strong(published, fresh.get(), std::memory_order_acq_rel,
                                         std::memory_order_acquire))
            return fresh.release();
        return published; // another thread was first
    } catch (...) {
        return nullptr; // malformed data or no memory: no exception crosses generated code
    }
}

void frac_aot_attractor_distance_release(frac::ir::ExternalData* record) noexcept {
    std::atomic_ref<const frac::ir::ExternalFunction*> slot(record->function);
    delete slot.exchange(nullptr, std::memory_order_acq_rel);
}

} // extern "C"
