#include "frontend/suggest.hpp"

#include <algorithm>
#include <cctype>

namespace frac::front {

std::size_t edit_distance(const std::string& a, const std::string& b) {
    const auto lower = [](char c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); };
    const std::size_t n = a.size(), m = b.size();
    std::vector<std::vector<std::size_t>> d(n + 1, std::vector<std::size_t>(m + 1));
    for (std::size_t i = 0; i <= n; ++i) d[i][0] = i;
    for (std::size_t j = 0; j <= m; ++j) d[0][j] = j;
    for (std::size_t i = 1; i <= n; ++i)
        for (std::size_t j = 1; j <= m; ++j) {
            const std::size_t cost = lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1;
            d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
            if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) && lower(a[i - 2]) == lower(b[j - 1]))
                d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
        }
    return d[n][m];
}

std::optional<std::string> closest_name(const std::string& name, const std::vector<std::string>& candidates) {
    // A name of one or two letters is close to too many others: only a difference of case counts.
    const std::size_t limit =
        name.size() <= 2 ? 0 : std::max<std::size_t>(1, std::min<std::size_t>(2, name.size() / 3));
    std::optional<std::string> best;
    // The distance takes time quadratic in the lengths (a name of 10^6 letters took minutes): longer names
    // get no suggestion, and a length difference above the limit is already too far.
    constexpr std::size_t max_suggested_length = 128;
    if (name.size() > max_suggested_length) return best;
    std::size_t best_distance = limit + 1;
    for (const std::string& c : candidates) {
        if (c == name || c.size() > name.size() + limit || name.size() > c.size() + limit) continue;
        const std::size_t d = edit_distance(name, c);
        if (d < best_distance) {
            best_distance = d;
            best = c;
        }
    }
    return best;
}

std::string list_names(const std::vector<std::string>& names) {
    if (names.empty()) return "none";
    std::string s;
    for (std::size_t i = 0; i < names.size(); ++i) s += (i == 0 ? "" : ", ") + names[i];
    return s;
}

} // namespace frac::front
