#include "io/snapshot.hpp"

#include <algorithm>
#include <regex>

#include <fmt/format.h>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/checkpoint_file.hpp"

namespace boycott::io {

namespace fs = std::filesystem;

namespace {

std::string data_item(const std::string& file, const std::string& name, const std::string& dims) {
  return fmt::format(
      "<DataItem Format=\"HDF\" NumberType=\"Float\" Precision=\"8\" Dimensions=\"{}\">{}:/{}</DataItem>",
      dims, file, name);
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
  std::string parts, fluid;
  for (const auto& [idx, path] : files) {
    CheckpointReader r(path, CheckpointReader::Verify::kNo);  // this run's own files, just written
    const double t = r.scalar("time");
    const std::string f = path.filename().string();
    const auto n = r.doubles("particles/x").size();
    parts +=
        fmt::format("<Grid Name=\"particles_{}\" GridType=\"Uniform\">\n<Time Value=\"{:.9g}\"/>\n", idx, t);
    parts += fmt::format("<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"{}\"/>\n", n);
    parts += "<Geometry GeometryType=\"X_Y_Z\">\n";
    for (const char* c : {"x", "y", "z"})
      parts += data_item(f, std::string("particles/") + c, std::to_string(n)) + "\n";
    parts += "</Geometry>\n";
    for (const char* a : {"vx", "vy", "vz", "radius"})
      parts += fmt::format("<Attribute Name=\"{}\" AttributeType=\"Scalar\" Center=\"Node\">{}</Attribute>\n",
                           a, data_item(f, std::string("particles/") + a, std::to_string(n)));
    parts += "</Grid>\n";
    const auto names = r.string("fluid_fields");
    if (!names.empty()) {
      const std::string cells = fmt::format("{} {} {}", g.n[2], g.n[1], g.n[0]);
      fluid +=
          fmt::format("<Grid Name=\"fluid_{}\" GridType=\"Uniform\">\n<Time Value=\"{:.9g}\"/>\n", idx, t);
      fluid += fmt::format("<Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"{} {} {}\"/>\n", g.n[2] + 1,
                           g.n[1] + 1, g.n[0] + 1);
      fluid += "<Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n";
      fluid += "<DataItem Format=\"XML\" Dimensions=\"3\">0 0 0</DataItem>\n";
      fluid += fmt::format("<DataItem Format=\"XML\" Dimensions=\"3\">{:.9g} {:.9g} {:.9g}</DataItem>\n",
                           g.dx(2), g.dx(1), g.dx(0));
      fluid += "</Geometry>\n";
      std::size_t pos = 0;
      while (pos < names.size()) {
        const auto end = std::min(names.find(',', pos), names.size());
        const std::string nm = names.substr(pos, end - pos);
        fluid +=
            fmt::format("<Attribute Name=\"{}\" AttributeType=\"Scalar\" Center=\"Cell\">{}</Attribute>\n",
                        nm, data_item(f, "fluid/" + nm, cells));
        pos = end + 1;
      }
      fluid += "</Grid>\n";
    }
  }
  x +=
      "<Grid Name=\"particles\" GridType=\"Collection\" CollectionType=\"Temporal\">\n" + parts + "</Grid>\n";
  if (!fluid.empty())
    x += "<Grid Name=\"fluid\" GridType=\"Collection\" CollectionType=\"Temporal\">\n" + fluid + "</Grid>\n";
  x += "</Domain>\n</Xdmf>\n";
  write_file_atomic(dir / "fields.xmf", x);
}

}  // namespace

fs::path write_snapshot(const fs::path& run_dir, int index, const SnapshotData& d, const GridSpec& g) {
  const fs::path dir = run_dir / "snapshots";
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw StorageError(fmt::format("cannot create {}: {}", dir.string(), ec.message()));
  const fs::path path = dir / fmt::format("snap_{:05d}.h5", index);
  {
    CheckpointWriter w(path);
    w.put("time", d.time_s);
    w.put_group("particles");
    for (const auto& [name, v] :
         std::initializer_list<std::pair<const char*, const std::vector<double>*>>{{"x", &d.x},
                                                                                   {"y", &d.y},
                                                                                   {"z", &d.z},
                                                                                   {"vx", &d.vx},
                                                                                   {"vy", &d.vy},
                                                                                   {"vz", &d.vz},
                                                                                   {"radius", &d.radius}})
      w.put(std::string("particles/") + name, *v);
    std::string names;
    if (!d.cell_fields.empty()) {
      w.put_group("fluid");
      for (const auto& [name, v] : d.cell_fields) {
        w.put_3d("fluid/" + name,
                 {static_cast<std::size_t>(g.n[2]), static_cast<std::size_t>(g.n[1]),
                  static_cast<std::size_t>(g.n[0])},
                 v);
        names += (names.empty() ? "" : ",") + name;
      }
    }
    w.put_string("fluid_fields", names);
    w.commit();
  }
  write_index(dir, g);
  return path;
}

}  // namespace boycott::io
