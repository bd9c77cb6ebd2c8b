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
  // The counts are the first three runs of digits after the keyword, comments skipped (vertices,
  // faces, edges); a run is read as assimp reads it, its leading digits ("444z" is 444).
  unsigned long long counts[3] = {0, 0, 0};
  int found = 0;
  std::size_t i = counts_start(bytes), after_faces = bytes.size();
  while (found < 3 && i < bytes.size()) {
    const char c = bytes[i];
    if (c == '#') {
      i = std::min(bytes.find('\n', i), bytes.size());
    } else if (std::isdigit(static_cast<unsigned char>(c))) {
      unsigned long long value = 0;
      for (; i < bytes.size() && std::isdigit(static_cast<unsigned char>(bytes[i])); ++i) {
        value = std::min<unsigned long long>(value * 10 + (bytes[i] - '0'), 1ull << 40);
      }
      counts[found++] = value;
      if (found == 2) after_faces = i;
    } else {
      ++i;
    }
  }
  if (found < 2) return;  // assimp says what is missing
  // Lines from the rest of the counts' line on (a last line without its newline counts too).
  const auto lines =
      static_cast<unsigned long long>(
          std::count(bytes.begin() + static_cast<std::ptrdiff_t>(after_faces), bytes.end(), '\n')) +
      (bytes.back() != '\n' ? 1 : 0);
  if (counts[0] + counts[1] > lines) {
    throw ConfigError(path, "OFF header promises " + std::to_string(counts[0]) + " vertices and " +
                                std::to_string(counts[1]) + " faces, one a line, but only " +
                                std::to_string(lines) + " lines follow the counts");
  }
  // assimp allocates by the edge count too (a 66-byte file asking for 444444444 edges took 7 GB);
  // every edge belongs to a face, whose indices take at least two bytes each.
  if (found == 3 && counts[2] > bytes.size()) {
    throw ConfigError(path, "OFF header promises " + std::to_string(counts[2]) +
                                " edges, more than a file of " + std::to_string(bytes.size()) +
                                " bytes can hold");
  }
}

}  // namespace ambfplus::io
