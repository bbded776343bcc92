#include "evio/core/io/health_txt.h"

#include <array>
#include <cmath>
#include <utility>

namespace evio::io {

namespace {
constexpr std::size_t kValues = 9;

int countColumn(const TimedTableReader& reader, double v, const char* column) {
  if (!(v >= 0.0) || v != std::floor(v) || v > 1e9) reader.fail(column, "must be a whole number >= 0");
  return static_cast<int>(v);
}
}  // namespace

HealthWriter::HealthWriter(std::string path, const std::vector<std::string>& header)
    : table_(std::move(path), header) {}

void HealthWriter::append(const HealthRow& r) {
  const std::array<double, kValues> v = {r.nis, static_cast<double>(r.dof), static_cast<double>(r.accepted),
                                         static_cast<double>(r.rejected), static_cast<double>(r.slam),
                                         static_cast<double>(r.msckf), r.sigma_p_m, r.nis_accepted,
                                         static_cast<double>(r.dof_accepted)};
  table_.append(r.t_ns, v.data(), v.size());
}

void HealthWriter::close() { table_.close(); }

std::vector<HealthRow> readHealthText(const std::string& path) {
  TimedTableReader reader(
      path, {"nis", "dof", "accepted", "rejected", "slam", "msckf", "sigma_p_m", "nis_accepted", "dof_accepted"},
      "health.txt", 2);
  std::vector<HealthRow> out;
  HealthRow r;
  std::array<double, kValues> v{};
  while (reader.next(&r.t_ns, v.data())) {
    if (v[0] < 0.0) reader.fail("nis", "must be >= 0");
    r.nis = v[0];
    r.dof = countColumn(reader, v[1], "dof");
    r.accepted = countColumn(reader, v[2], "accepted");
    r.rejected = countColumn(reader, v[3], "rejected");
    r.slam = countColumn(reader, v[4], "slam");
    r.msckf = countColumn(reader, v[5], "msckf");
    if (v[6] < 0.0) reader.fail("sigma_p_m", "must be >= 0");
    r.sigma_p_m = v[6];
    if (reader.valueCount() == kValues) {
      if (!(v[7] >= 0.0)) reader.fail("nis_accepted", "must be >= 0");
      r.nis_accepted = v[7];
      r.dof_accepted = countColumn(reader, v[8], "dof_accepted");
    } else {  // a file from before the two columns: every innovation as if accepted
      r.nis_accepted = r.nis;
      r.dof_accepted = r.dof;
    }
    out.push_back(r);
  }
  return out;
}

}  // namespace evio::io
