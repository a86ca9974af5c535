#include "frontend/consteval.hpp"

#include <fmt/format.h>

namespace frac::front {

namespace {

std::string component_text(const ConstantComponent& c) {
    if (c.exact) return c.exact->to_string();
    if (c.enclosure.lo == c.enclosure.hi) return fmt::format("{}", c.enclosure.lo);
    return fmt::format("[{}, {}]", c.enclosure.lo, c.enclosure.hi);
}

std::string value_text(const ConstantValue& v) {
    if (v.item) return v.item->name;
    if (v.linear) {
        const ir::Operator& m = v.linear->transform
                                    ? v.linear->in(v.linear->dimension ? v.linear->dimension : 2)
                                    : v.linear->in(0);
        std::string rows;
        for (std::size_t r = 0; r < m.rows(); ++r) {
            rows += r ? ", [" : "[";
            for (std::size_t c = 0; c < m.cols(); ++c) {
                ConstantComponent e;
                if (m.exact) e.exact = std::make_shared<const num::Rational>((*m.exact)(r, c));
                e.enclosure = m.enclosure(r, c);
                rows += (c ? ", " : "") + component_text(e);
            }
            rows += "]";
        }
        return fmt::format("{}[{}]", v.linear->transform && !v.linear->dimension ? "(in R2) " : "", rows);
    }
    switch (v.kind) {
    case ValueKind::boolean: {
        const Interval t = v.components.at(0).enclosure;
        return t.lo == 1 ? "true" : t.hi == 0 ? "false" : "unknown";
    }
    case ValueKind::point: {
        std::string s;
        for (const ConstantComponent& c : v.components) s += (s.empty() ? "" : ", ") + component_text(c);
        return "(" + s + ")";
    }
    case ValueKind::interval:
    case ValueKind::box: {
        std::string s;
        for (const Interval& i : v.box) s += (s.empty() ? "" : " × ") + fmt::format("[{}, {}]", i.lo, i.hi);
        return s;
    }
    case ValueKind::scalar: break;
    }
    return component_text(v.components.at(0));
}

} // namespace

std::string print_constants(const Program& program, const ConstantValues& values, std::uint32_t file) {
    std::string out;
    for (const Item& it : program.items) {
        if (it.kind != ItemKind::const_ || (file != 0 && it.loc.file != file)) continue;
        auto v = values.values.find(&it);
        out += fmt::format("const {} = {}\n", it.name,
                           v == values.values.end() ? "(not evaluated)" : value_text(v->second));
    }
    return out;
}

} // namespace frac::front
