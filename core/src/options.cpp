#include "evio/core/options.h"

#include <sstream>

namespace evio {
namespace {
std::string show(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}
}  // namespace

void requirePositive(std::string_view field, double value) {
  if (!(value > 0.0) || !std::isfinite(value))
    throw Error(std::string(field) + ": must be a finite number > 0 (got " + show(value) + ")");
}

void requireNonNegative(std::string_view field, double value) {
  if (!(value >= 0.0) || !std::isfinite(value))
    throw Error(std::string(field) + ": must be a finite number >= 0 (got " + show(value) + ")");
}

void requireInRange(std::string_view field, double value, double lo, double hi) {
  if (!(value >= lo && value <= hi))
    throw Error(std::string(field) + ": must be in [" + show(lo) + ", " + show(hi) + "] (got " +
                show(value) + ")");
}

void requireField(bool condition, std::string_view field, std::string_view message) {
  if (!condition) throw Error(std::string(field) + ": " + std::string(message));
}

}  // namespace evio
