#include "io/snapshot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <regex>
#include <stdexcept>

#include <fmt/format.h>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/checkpoint_file.hpp"

namespace boycott::io {

namespace fs = std::filesystem;

double wrap_into_box(double x, double length) {
  double r = std::fmod(x, length);
  if (r < 0) r += length;
  if (r >= length) r -= length;  // -tiny + length rounds to length
  return r;
}

namespace {

std::string data_item(const std::string& file, const std::string& name, const std::string& dims,
                      const char* type = "Float") {
  return fmt::format(
      "<DataItem Format=\"HDF\" NumberType=\"{}\" Precision=\"8\" Dimensions=\"{}\">{}:/{}</DataItem>", type,
      dims, file, name);
}

std::string attribute(const char* name, const char* kind, const char* center, const std::string& item) {
  return fmt::format("<Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"{}\">{}</Attribute>\n", name, kind,
                     center, item);
}

/// One time of the index: a spatial collection of the particle point set and the fluid grid.
std::string index_entry(const fs::path& path, int idx, const GridSpec& g) {
  CheckpointReader r(path, CheckpointReader::Verify::kNo);  // this run's own files, just written
  const std::string f = path.filename().string();
  std::string s = fmt::format(
      "<Grid Name=\"snap_{:05d}\" GridType=\"Collection\" CollectionType=\"Spatial\">\n<Time "
      "Value=\"{:.9g}\"/>\n",
      idx, r.scalar("time"));
  const std::size_t n = r.dims("particles/id").at(0);
  if (n > 0) {
    const std::string n1 = std::to_string(n), n3 = fmt::format("{} 3", n);
    s += "<Grid Name=\"particles\" GridType=\"Uniform\">\n";
    s += fmt::format(
        "<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"{}\" NodesPerElement=\"1\"/>\n", n);
    s += "<Geometry GeometryType=\"XYZ\">" + data_item(f, "particles/position", n3) + "</Geometry>\n";
    s += attribute("id", "Scalar", "Node", data_item(f, "particles/id", n1, "Int"));
    s += attribute("radius", "Scalar", "Node", data_item(f, "particles/radius", n1));
    s += attribute("velocity", "Vector", "Node", data_item(f, "particles/velocity", n3));
    s += attribute("angular_velocity", "Vector", "Node", data_item(f, "particles/angular_velocity", n3));
    s += "</Grid>\n";
  }
  const auto names = r.strings("fluid_fields");
  if (!names.empty()) {
    const std::string cells = fmt::format("{} {} {}", g.n[2], g.n[1], g.n[0]);
    s += "<Grid Name=\"fluid\" GridType=\"Uniform\">\n";
    s += fmt::format("<Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"{} {} {}\"/>\n", g.n[2] + 1,
                     g.n[1] + 1, g.n[0] + 1);
    s += "<Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n";
    s += "<DataItem Format=\"XML\" Dimensions=\"3\">0 0 0</DataItem>\n";
    s += fmt::format("<DataItem Format=\"XML\" Dimensions=\"3\">{:.9g} {:.9g} {:.9g}</DataItem>\n", g.dx(2),
                     g.dx(1), g.dx(0));
    s += "</Geometry>\n";
    for (const auto& nm : names)
      s += attribute(nm.c_str(), "Scalar", "Cell", data_item(f, "fluid/" + nm, cells));
    s += "</Grid>\n";
  }
  return s + "</Grid>\n";
}

void write_index(const fs::path& dir, const GridSpec& g) {
  static const std::regex re(R"(snap_(\d+)\.h5)");
  std::vector<std::pair<int, fs::path>> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    std::smatch m;
    const std::string name = e.path().filename().string();
    if (std::regex_match(name, m, re)) files.emplace_back(std::stoi(m[1]), e.path());
  }
  std::sort(files.begin(), files.end());
  std::string x = "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n<Domain>\n";
  x += "<Grid Name=\"snapshots\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  std::vector<std::string> left_out;
  for (const auto& [idx, path] : files) {
    // A snapshot of the layout before particles/id (a run resumed across the change) is left out.
    if (!CheckpointReader(path, CheckpointReader::Verify::kNo).has("particles/id")) {
      left_out.push_back(path.filename().string());
      continue;
    }
    x += index_entry(path, idx, g);
  }
  // Said once per run (the index is rewritten with every snapshot), not left for the user to find.
  static bool told = false;
  if (!left_out.empty() && !told) {
    told = true;
    std::fprintf(stderr,
                 "note: %zu snapshot(s) of an older layout (no particles/id), first %s, are left out of %s; "
                 "they stay readable with h5dump\n",
                 left_out.size(), left_out.front().c_str(), (dir / "fields.xmf").c_str());
  }
  x += "</Grid>\n</Domain>\n</Xdmf>\n";
  write_file_atomic(dir / "fields.xmf", x);
}

}  // namespace

fs::path write_snapshot(const fs::path& run_dir, int index, const SnapshotData& d, const GridSpec& g) {
  const std::size_t n = d.id.size();
  for (const auto* v : {&d.x, &d.y, &d.z, &d.vx, &d.vy, &d.vz, &d.wx, &d.wy, &d.wz, &d.radius})
    if (v->size() != n)
      throw std::logic_error(fmt::format("snapshot: {} particle ids but an array of {}", n, v->size()));
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return d.id[a] < d.id[b]; });
  std::vector<std::int64_t> ids(n);
  std::vector<double> pos(3 * n), vel(3 * n), ang(3 * n), radius(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = order[k];
    ids[k] = d.id[i];
    radius[k] = d.radius[i];
    const double p[3] = {d.x[i], d.y[i], d.z[i]};
    for (int c = 0; c < 3; ++c) pos[3 * k + c] = g.periodic[c] ? wrap_into_box(p[c], g.length_m[c]) : p[c];
    vel[3 * k] = d.vx[i], vel[3 * k + 1] = d.vy[i], vel[3 * k + 2] = d.vz[i];
    ang[3 * k] = d.wx[i], ang[3 * k + 1] = d.wy[i], ang[3 * k + 2] = d.wz[i];
  }
  const fs::path dir = run_dir / "snapshots";
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw StorageError(fmt::format("cannot create {}: {}", dir.string(), ec.message()));
  const fs::path path = dir / fmt::format("snap_{:05d}.h5", index);
  {
    CheckpointWriter w(path);
    w.put("time", d.time_s);
    w.put_group("particles");
    w.put("particles/id", ids);
    w.put_2d("particles/position", n, 3, pos);
    w.put_2d("particles/velocity", n, 3, vel);
    w.put_2d("particles/angular_velocity", n, 3, ang);
    w.put("particles/radius", radius);
    std::vector<std::string> names;
    if (!d.cell_fields.empty()) {
      w.put_group("fluid");
      for (const auto& [name, v] : d.cell_fields) {
        w.put_3d("fluid/" + name,
                 {static_cast<std::size_t>(g.n[2]), static_cast<std::size_t>(g.n[1]),
                  static_cast<std::size_t>(g.n[0])},
                 v);
        names.push_back(name);
      }
    }
    w.put_strings("fluid_fields", names);
    w.commit();
  }
  write_index(dir, g);
  return path;
}

}  // namespace boycott::io
