// Snapshots as ParaView reads them: every HDF5 path the XDMF index names exists with the shape
// and number type the index gives (read back with the HDF5 C API, not with the writer's reader),
// one temporal collection lists every snapshot file, the fluid field names are HDF5 strings,
// particles are stored in id order with positions inside the periodic box. Once for a small
// system written directly, once for a coupled run (on 2 ranks as well: particles decomposed
// over the ranks and gathered to rank 0).
#include <gtest/gtest.h>
#include <hdf5.h>
#include <mpi.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/case_params.hpp"
#include "core/error.hpp"
#include "io/checkpoint_file.hpp"
#include "io/snapshot.hpp"
#include "runs/run_case.hpp"
#include "scenes/scene.hpp"

namespace boycott {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& f) {
  std::ifstream in(f);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<hsize_t> shape_of(hid_t ds) {
  const hid_t space = H5Dget_space(ds);
  std::vector<hsize_t> d(static_cast<std::size_t>(std::max(0, H5Sget_simple_extent_ndims(space))));
  if (!d.empty()) H5Sget_simple_extent_dims(space, d.data(), nullptr);
  H5Sclose(space);
  return d;
}

template <class T>
std::vector<T> read_all(hid_t file, const char* name, hid_t type) {
  const hid_t ds = H5Dopen2(file, name, H5P_DEFAULT);
  EXPECT_GE(ds, 0) << name;
  if (ds < 0) return {};
  std::size_t n = 1;
  for (auto d : shape_of(ds)) n *= d;
  std::vector<T> v(n);
  EXPECT_GE(H5Dread(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), 0) << name;
  H5Dclose(ds);
  return v;
}

struct IndexFacts {
  int times = 0, items = 0;
  std::size_t particles_first = 0;  ///< rows of particles/id in the first snapshot
};

/// Checks the index of DIR/snapshots against its HDF5 files; `box` the periodic lengths (x, z).
IndexFacts check_snapshots(const fs::path& dir, double length_x, double height_z) {
  IndexFacts facts;
  const fs::path sd = dir / "snapshots";
  const std::string text = slurp(sd / "fields.xmf");
  // Well-formed: every element closed in order.
  {
    static const std::regex tag(R"(<(/?)([A-Za-z?][^ >/]*)[^>]*?(/?)>)");
    std::vector<std::string> stack;
    for (std::sregex_iterator it(text.begin(), text.end(), tag), end; it != end; ++it) {
      const std::string name = (*it)[2].str();
      if (name[0] == '?' || (*it)[3].str() == "/") continue;
      if ((*it)[1].str() == "/") {
        EXPECT_FALSE(stack.empty()) << "unexpected </" << name << ">";
        if (stack.empty()) return facts;
        EXPECT_EQ(stack.back(), name);
        stack.pop_back();
      } else {
        stack.push_back(name);
      }
    }
    EXPECT_TRUE(stack.empty());
  }
  // One temporal collection, one time per snapshot file, times increasing.
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(sd)) files += e.path().extension() == ".h5";
  static const std::regex temporal(R"(CollectionType="Temporal")"), time(R"(<Time Value="([^"]+)\"/>)");
  EXPECT_EQ(std::distance(std::sregex_iterator(text.begin(), text.end(), temporal), std::sregex_iterator()),
            1);
  double last = -1e300;
  for (std::sregex_iterator it(text.begin(), text.end(), time), end; it != end; ++it) {
    const double t = std::stod((*it)[1].str());
    EXPECT_GT(t, last);
    last = t;
    ++facts.times;
  }
  EXPECT_EQ(static_cast<std::size_t>(facts.times), files);
  // Every HDF5 item: the path exists with the shape and number type the index gives.
  static const std::regex item(
      R"re(<DataItem Format="HDF" NumberType="(\w+)" Precision="8" Dimensions="([0-9 ]+)">([^:<]+):/([^<]+)</DataItem>)re");
  for (std::sregex_iterator it(text.begin(), text.end(), item), end; it != end; ++it) {
    std::istringstream dims((*it)[2].str());
    std::vector<hsize_t> want;
    for (hsize_t v; dims >> v;) want.push_back(v);
    const fs::path file = sd / (*it)[3].str();
    const std::string path = (*it)[4].str();
    const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    EXPECT_GE(f, 0) << file;
    if (f < 0) continue;
    const hid_t ds = H5Dopen2(f, path.c_str(), H5P_DEFAULT);
    EXPECT_GE(ds, 0) << file << ":" << path;
    if (ds >= 0) {
      EXPECT_EQ(shape_of(ds), want) << path;
      const hid_t type = H5Dget_type(ds);
      EXPECT_EQ(H5Tget_class(type), (*it)[1].str() == "Int" ? H5T_INTEGER : H5T_FLOAT) << path;
      EXPECT_EQ(H5Tget_size(type), 8u) << path;
      H5Tclose(type);
      H5Dclose(ds);
    }
    H5Fclose(f);
    ++facts.items;
  }
  // Each file: names as strings, every named fluid field present; ids ascending, positions in the box.
  bool first = true;
  for (const auto& e : fs::directory_iterator(sd)) {
    if (e.path().extension() != ".h5") continue;
    const hid_t f = H5Fopen(e.path().c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    EXPECT_GE(f, 0) << e.path();
    if (f < 0) continue;
    const hid_t ds = H5Dopen2(f, "fluid_fields", H5P_DEFAULT);
    EXPECT_GE(ds, 0) << e.path();
    if (ds < 0) {
      H5Fclose(f);
      continue;
    }
    const hid_t type = H5Dget_type(ds);
    EXPECT_EQ(H5Tget_class(type), H5T_STRING);
    const std::size_t len = H5Tget_size(type), n = shape_of(ds).at(0);
    std::vector<char> buf(len * n + 1, '\0');
    if (n > 0) {
      EXPECT_GE(H5Dread(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf.data()), 0);
    }
    for (std::size_t k = 0; k < n; ++k) {
      const std::string name(buf.data() + k * len, strnlen(buf.data() + k * len, len));
      EXPECT_FALSE(name.empty());
      EXPECT_GT(H5Lexists(f, ("fluid/" + name).c_str(), H5P_DEFAULT), 0) << name;
      EXPECT_NE(text.find("Attribute Name=\"" + name + "\""), std::string::npos) << name;
    }
    H5Tclose(type);
    H5Dclose(ds);
    const auto ids = read_all<std::int64_t>(f, "particles/id", H5T_NATIVE_INT64);
    for (std::size_t k = 1; k < ids.size(); ++k) EXPECT_LT(ids[k - 1], ids[k]);
    const auto pos = read_all<double>(f, "particles/position", H5T_NATIVE_DOUBLE);
    EXPECT_EQ(pos.size(), 3 * ids.size());
    for (std::size_t k = 0; k < ids.size(); ++k) {
      EXPECT_GE(pos[3 * k], 0.0);
      EXPECT_LT(pos[3 * k], length_x);
      EXPECT_GE(pos[3 * k + 2], 0.0);
      EXPECT_LT(pos[3 * k + 2], height_z);
    }
    if (first) facts.particles_first = ids.size();
    first = false;
    H5Fclose(f);
  }
  return facts;
}

TEST(SnapshotFormat, WrittenSystemReadsBackInIdOrderWithVectorsAndStringNames) {
  GridSpec g;
  g.n = {4, 3, 2};
  g.length_m = {0.02, 0.006, 0.01};
  g.periodic = {true, false, true};
  io::SnapshotData d;
  d.id = {4, 0, 3, 1, 2};  // any order in, id order out
  for (const auto id : d.id) {
    const double k = static_cast<double>(id);
    d.x.push_back(0.001 * k), d.y.push_back(0.001), d.z.push_back(0.002 * k);
    d.vx.push_back(10 * k + 1), d.vy.push_back(10 * k + 2), d.vz.push_back(10 * k + 3);
    d.wx.push_back(-k), d.wy.push_back(-2 * k), d.wz.push_back(-3 * k), d.radius.push_back(1e-4 * (k + 1));
  }
  d.x[0] = 0.02 + 4e-6;  // id 4 just past the periodic side in x
  d.z[1] = -1e-6;        // id 0 just below z = 0
  for (const char* name : {"alpha_f", "pressure", "u"})
    d.cell_fields.emplace_back(name, std::vector<double>(24, 1.0));
  const fs::path dir = fs::temp_directory_path() / "boycott_snapshot_format";
  fs::remove_all(dir);
  d.time_s = 0.5;
  io::write_snapshot(dir, 0, d, g);
  d.time_s = 1.0;
  io::write_snapshot(dir, 1, d, g);
  const auto facts = check_snapshots(dir, 0.02, 0.01);
  EXPECT_EQ(facts.times, 2);
  EXPECT_EQ(facts.items, 2 * (5 + 3));  // position, id, radius, velocity, angular velocity; 3 fields
  EXPECT_EQ(facts.particles_first, 5u);

  const hid_t f = H5Fopen((dir / "snapshots" / "snap_00001.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  EXPECT_EQ(read_all<std::int64_t>(f, "particles/id", H5T_NATIVE_INT64),
            (std::vector<std::int64_t>{0, 1, 2, 3, 4}));
  const auto pos = read_all<double>(f, "particles/position", H5T_NATIVE_DOUBLE);
  const auto vel = read_all<double>(f, "particles/velocity", H5T_NATIVE_DOUBLE);
  const auto ang = read_all<double>(f, "particles/angular_velocity", H5T_NATIVE_DOUBLE);
  const auto rad = read_all<double>(f, "particles/radius", H5T_NATIVE_DOUBLE);
  const auto time = read_all<double>(f, "time", H5T_NATIVE_DOUBLE);
  H5Fclose(f);
  ASSERT_EQ(vel.size(), 15u);
  ASSERT_EQ(ang.size(), 15u);
  for (int k = 0; k < 5; ++k) {
    EXPECT_EQ(vel[3 * k], 10 * k + 1);
    EXPECT_EQ(vel[3 * k + 2], 10 * k + 3);
    EXPECT_EQ(ang[3 * k + 1], -2 * k);
    EXPECT_EQ(rad[k], 1e-4 * (k + 1));
  }
  EXPECT_NEAR(pos[3 * 4], 4e-6, 1e-15);     // id 4 wrapped to the left side
  EXPECT_NEAR(pos[2], 0.01 - 1e-6, 1e-15);  // id 0 wrapped to the top
  EXPECT_EQ(pos[3 * 2 + 1], 0.001);         // y (a wall-bounded axis) as it was
  EXPECT_EQ(time, std::vector<double>{1.0});
}

TEST(SnapshotFormat, OlderLayoutSnapshotIsLeftOutOfTheIndexWithANote) {
  // A run resumed across the layout change holds snapshots without particles/id: the XDMF index
  // cannot describe them, so they are left out, and the run says so instead of dropping them in
  // silence.
  GridSpec g;
  g.n = {2, 2, 2};
  g.length_m = {0.01, 0.006, 0.01};
  g.periodic = {true, false, true};
  io::SnapshotData d;
  d.id = {0};
  d.x = {0.001}, d.y = {0.001}, d.z = {0.001}, d.vx = {0}, d.vy = {0}, d.vz = {0};
  d.wx = {0}, d.wy = {0}, d.wz = {0}, d.radius = {1e-4};
  d.cell_fields.emplace_back("alpha_f", std::vector<double>(8, 1.0));
  const fs::path dir = fs::temp_directory_path() / "boycott_snapshot_older_layout";
  fs::remove_all(dir);
  fs::create_directories(dir / "snapshots");
  {
    // Complete and checksummed like every snapshot, but with positions and no particles/id.
    io::CheckpointWriter w(dir / "snapshots" / "snap_00000.h5");
    w.put("time", 0.1);
    w.put_group("particles");
    w.put_2d("particles/position", 1, 3, std::vector<double>{0.001, 0.001, 0.001});
    w.commit();
  }
  d.time_s = 0.2;
  testing::internal::CaptureStderr();
  io::write_snapshot(dir, 1, d, g);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("older layout"), std::string::npos) << err;
  EXPECT_NE(err.find("snap_00000.h5"), std::string::npos) << err;
  const std::string xmf = slurp(dir / "snapshots" / "fields.xmf");
  EXPECT_EQ(xmf.find("snap_00000.h5"), std::string::npos);
  EXPECT_NE(xmf.find("snap_00001.h5"), std::string::npos);
}

TEST(SnapshotFormat, CoupledRunSnapshotsReadBackOnEveryRankCount) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  CaseParams p =
      parse_case_file(std::string(BOYCOTT_SOURCE_DIR) + "/studies/cases/inclined_settling_smoke.toml");
  apply_override(p, "time.end=0.02");
  apply_override(p, "time.average_from=0.01");
  apply_override(p, "output.snapshot_times=[0.005, 0.015]");
  const fs::path d = fs::temp_directory_path() / fmt::format("boycott_snapshot_run_{}", size);
  if (rank == 0) fs::remove_all(d);
  MPI_Barrier(MPI_COMM_WORLD);
  scenes::RunContext ctx;
  ctx.quiet = true;
  ctx.out_dir = d;
  ASSERT_EQ(runs::run_case(p, ctx), kExitOk);
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank != 0) return;
  const auto facts = check_snapshots(d, p.domain.length_x_m, p.domain.height_z_m);
  EXPECT_EQ(facts.times, 2);
  EXPECT_EQ(facts.items, 2 * (5 + 5));  // 5 particle items, 5 fluid fields
  std::ifstream in(d / "summary.json");
  EXPECT_EQ(facts.particles_first, nlohmann::json::parse(in)["particle_count"].get<std::size_t>());
}

}  // namespace
}  // namespace boycott
