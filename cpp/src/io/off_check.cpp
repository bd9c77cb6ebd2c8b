// The count check of an OFF file (a keyword such as OFF, COFF or STOFF, then the vertex, face and
// edge counts, then one vertex or face a line; '#' starts a comment), done before assimp reads it.

#include "io/off_check.h"

#include <algorithm>
#include <cctype>
#include <string>

#include "ambfplus/errors.h"

namespace ambfplus::io {

namespace {

// Where the counts begin: after the keyword when the first line that is not a comment holds
// one ("OFF4 2 0" counts 4 vertices, as assimp reads it), else at that line.
std::size_t counts_start(const std::string& bytes) {
  std::size_t at = 0;
  while (at < bytes.size()) {
    const std::size_t text = bytes.find_first_not_of(" \t\r\n", at);
    if (text == std::string::npos) return bytes.size();
    if (bytes[text] != '#') {
      const std::size_t end = std::min(bytes.find('\n', text), bytes.size());
      const std::size_t keyword = bytes.substr(text, end - text).find("OFF");
      return keyword == std::string::npos ? text : text + keyword + 3;
    }
    at = std::min(bytes.find('\n', text), bytes.size());
  }
  return bytes.size();
}

}  // namespace

void check_off(const std::string& path, const std::string& bytes) {
  // The counts are the first two runs of digits after the keyword, comments skipped; a run is
  // read as assimp reads it, its leading digits ("444z" is 444).
  unsigned long long counts[2] = {0, 0};
  int found = 0;
  std::size_t i = counts_start(bytes);
  while (found < 2 && i < bytes.size()) {
    const char c = bytes[i];
    if (c == '#') {
      i = std::min(bytes.find('\n', i), bytes.size());
    } else if (std::isdigit(static_cast<unsigned char>(c))) {
      unsigned long long value = 0;
      for (; i < bytes.size() && std::isdigit(static_cast<unsigned char>(bytes[i])); ++i) {
        value = std::min<unsigned long long>(value * 10 + (bytes[i] - '0'), 1ull << 40);
      }
      counts[found++] = value;
    } else {
      ++i;
    }
  }
  if (found < 2) return;  // assimp says what is missing
  // Lines from the rest of the counts' line on (a last line without its newline counts too).
  const auto lines = static_cast<unsigned long long>(std::count(
                         bytes.begin() + static_cast<std::ptrdiff_t>(i), bytes.end(), '\n')) +
                     (bytes.back() != '\n' ? 1 : 0);
  if (counts[0] + counts[1] > lines) {
    throw ConfigError(path, "OFF header promises " + std::to_string(counts[0]) + " vertices and " +
                                std::to_string(counts[1]) + " faces, one a line, but only " +
                                std::to_string(lines) + " lines follow the counts");
  }
}

}  // namespace ambfplus::io
