#include "evio/core/error.h"

namespace evio {
namespace {
// Built by appends: GCC 12 warns (-Wrestrict, a false positive) on chains of
// operator+ over string_views.
std::string located(std::string_view file, std::int64_t line) {
  std::string s;
  s.append(file);
  if (line > 0) {
    s.push_back(':');
    s.append(std::to_string(line));
  }
  s.append(": ");
  return s;
}
}  // namespace

Error Error::inFile(std::string_view file, std::int64_t line, std::string_view message) {
  std::string s = located(file, line);
  s.append(message);
  return Error(s);
}

Error Error::inField(std::string_view file, std::int64_t line, std::string_view field,
                     std::string_view message) {
  std::string s = located(file, line);
  s.append(field);
  s.append(": ");
  s.append(message);
  return Error(s);
}

}  // namespace evio
