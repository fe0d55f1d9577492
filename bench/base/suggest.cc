#include "bench/base/suggest.h"

#include <algorithm>
#include <cctype>
#include <vector>

namespace depthbench {

int EditDistance(std::string_view a, std::string_view b) {
  const auto lower = [](char c) { return std::tolower(static_cast<unsigned char>(c)); };
  const std::size_t n = a.size(), m = b.size();
  // Three rows of the dynamic-programming table: the swap of two
  // neighbours looks two rows back.
  std::vector<int> before(m + 1), previous(m + 1), current(m + 1);
  for (std::size_t j = 0; j <= m; ++j) previous[j] = static_cast<int>(j);
  for (std::size_t i = 1; i <= n; ++i) {
    current[0] = static_cast<int>(i);
    for (std::size_t j = 1; j <= m; ++j) {
      const int substitute = previous[j - 1] + (lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1);
      int best = std::min({previous[j] + 1, current[j - 1] + 1, substitute});
      if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) && lower(a[i - 2]) == lower(b[j - 1])) {
        best = std::min(best, before[j - 2] + 1);
      }
      current[j] = best;
    }
    std::swap(before, previous);
    std::swap(previous, current);
  }
  return previous[m];
}

std::string DidYouMean(std::string_view word, std::span<const std::string> names) {
  const std::string* nearest = nullptr;
  int best = 0;
  for (const std::string& name : names) {
    const int d = EditDistance(word, name);
    if (nearest == nullptr || d < best) {
      nearest = &name;
      best = d;
    }
  }
  const int allowed = std::max<int>(1, static_cast<int>(word.size()) / 3);
  if (nearest != nullptr && best > 0 && best <= allowed) return "; did you mean '" + *nearest + "'?";
  const std::string* started = nullptr;
  int count = 0;
  for (const std::string& name : names) {
    if (word.size() >= 2 && name.size() > word.size() && name.compare(0, word.size(), word) == 0) {
      started = &name;
      ++count;
    }
  }
  if (count == 1) return "; did you mean '" + *started + "'?";
  return "";
}

}  // namespace depthbench
