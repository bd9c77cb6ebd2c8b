// The count check of an OFF file (a keyword such as OFF or COFF, then the vertex, face and edge
// counts, then one vertex or face a line; '#' starts a comment), done before assimp reads it.

#include "io/off_check.h"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <sstream>
#include <vector>

#include "ambfplus/errors.h"

namespace ambfplus::io {

void check_off(const std::string& path, const std::string& bytes) {
  // The first three tokens (keyword, vertices, faces), comments skipped, and the line they end on.
  std::vector<std::string> tokens;
  std::size_t line_start = 0;
  std::size_t header_lines = 0;
  while (tokens.size() < 3 && line_start < bytes.size()) {
    std::size_t end = bytes.find('\n', line_start);
    if (end == std::string::npos) end = bytes.size();
    std::string line = bytes.substr(line_start, end - line_start);
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    for (std::string word; tokens.size() < 3 && words >> word;) tokens.push_back(word);
    ++header_lines;
    line_start = end + 1;
  }
  if (tokens.size() < 3) return;
  const std::string& keyword = tokens[0];
  if (keyword.size() < 3 || keyword.compare(keyword.size() - 3, 3, "OFF") != 0) return;
  unsigned long long counts[2] = {0, 0};
  for (int c = 0; c < 2; ++c) {
    const std::string& t = tokens[1 + c];
    if (t.empty() ||
        !std::all_of(t.begin(), t.end(), [](char ch) { return ch >= '0' && ch <= '9'; })) {
      return;
    }
    errno = 0;
    counts[c] = std::strtoull(t.c_str(), nullptr, 10);
    if (errno == ERANGE) counts[c] = ~0ull;
  }
  const std::size_t lines =
      static_cast<std::size_t>(std::count(
          bytes.begin() + static_cast<std::ptrdiff_t>(std::min(line_start, bytes.size())),
          bytes.end(), '\n')) +
      1;
  if (counts[0] > lines || counts[1] > lines || counts[0] + counts[1] > lines) {
    throw ConfigError(path, "OFF header (line " + std::to_string(header_lines) + ") promises " +
                                tokens[1] + " vertices and " + tokens[2] +
                                " faces, one a line, but only " + std::to_string(lines) +
                                " lines follow it");
  }
}

}  // namespace ambfplus::io
