// A KITTI sequence folder written by a test (removed when the test ends).
#pragma once

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "map_aided_fusion/dataset/kitti.hpp"

namespace maf_test {

namespace fs = std::filesystem;
using map_aided_fusion::dataset::KittiPoint;

struct Folder
{
  fs::path dir;
  explicit Folder(const std::string& name) : dir(fs::temp_directory_path() / ("maf_kitti_" + name + "_" +
                                                                              std::to_string(::getpid())))
  {
    fs::remove_all(dir);
    fs::create_directories(dir / "velodyne");
    fs::create_directories(dir / "labels");
  }
  ~Folder() { fs::remove_all(dir); }
  void text(const std::string& name, const std::string& content) const { std::ofstream(dir / name) << content; }
  void scan(int frame, const std::vector<KittiPoint>& pts) const
  {
    char n[32];
    std::snprintf(n, sizeof n, "velodyne/%06d.bin", frame);
    std::ofstream f(dir / n, std::ios::binary);
    f.write(reinterpret_cast<const char*>(pts.data()), static_cast<std::streamsize>(pts.size() * sizeof pts[0]));
  }
  void labels(int frame, const std::vector<std::uint32_t>& l) const
  {
    char n[32];
    std::snprintf(n, sizeof n, "labels/%06d.label", frame);
    std::ofstream f(dir / n, std::ios::binary);
    f.write(reinterpret_cast<const char*>(l.data()), static_cast<std::streamsize>(l.size() * sizeof l[0]));
  }
};

}  // namespace maf_test
