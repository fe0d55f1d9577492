// "Did you mean": the known name nearest a mistyped one.
#pragma once

#include <span>
#include <string>
#include <string_view>

namespace depthbench {

// Edits (insertions, deletions, substitutions, swaps of neighbours) that
// turn one string into the other, case ignored.
int EditDistance(std::string_view a, std::string_view b);

// "; did you mean 'NAME'?" for the name nearest `word`, when it is near
// enough to be a typo (a third of the word's length in edits, at least
// one), or when `word` is the start of exactly one name; else "".
std::string DidYouMean(std::string_view word, std::span<const std::string> names);

}  // namespace depthbench
