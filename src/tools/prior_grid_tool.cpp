// prior_grid_tool: loads a map as the PriorGridNodelet does, prints what it read and the cells per class,
// and optionally writes a PNG of the prior in the paper's colours. ROS-free.
//   prior_grid_tool [--config config/prior_grid.yaml] --map FILE [--origin LAT,LON[,ALT]] [--resolution R] [--png OUT.png] [--source KIND]
//                   [--metric] [--margin M] [--size S [--centre X,Y]] [--max-cells N]
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/core/prior_grid.hpp"
#include "map_aided_fusion/map_io/map_loader.hpp"
#include "map_aided_fusion/map_io/prior_grid_params.hpp"
#include "map_aided_fusion/map_io/prior_png.hpp"
#include "map_aided_fusion/map_io/yaml_params.hpp"

using namespace map_aided_fusion;

namespace {

constexpr double kDefaultResolution = 0.5;
constexpr double kDefaultMaxCells = 1.5e9;  // 1.5 GB of labels
constexpr int kExitUsage = 2;

void usage(std::ostream& os)
{
  os << "usage: prior_grid_tool [--config YAML] --map FILE [--origin LAT,LON[,ALT]] [--resolution R] [--png OUT.png]\n"
        "                       [--source auto|osm|geojson|shapefile|gpkg] [--metric] [--margin M]\n"
        "                       [--size S [--centre X,Y]] [--max-cells N]\n"
        "  --config YAML        parameters as in config/prior_grid.yaml (options given after it override them)\n"
        "  --map FILE           OpenStreetMap (.osm, .osm.pbf), GeoJSON, Shapefile or GeoPackage map\n"
        "  --origin LAT,LON,ALT origin of the map frame, degrees and metres (default: centre of the data)\n"
        "  --resolution R       cell side in metres (default 0.5)\n"
        "  --png OUT.png        writes the prior: roads white, buildings blue, other grey, north up\n"
        "  --metric             coordinates are already metric in the map frame\n"
        "  --margin M           metres added around the map's extent (default 0)\n"
        "  --size S             only the S m x S m square around --centre (map frame, default 0,0)\n"
        "  --max-cells N        refuse grids with more cells (default 1.5e9)\n";
}

std::vector<double> parseList(const std::string& s)
{
  std::vector<double> v;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
  {
    char* end = nullptr;
    const double x = std::strtod(item.c_str(), &end);
    if (end == item.c_str() || *end != '\0') return {};
    v.push_back(x);
  }
  return v;
}

bool parseOrigin(const std::string& s, map_io::MapLoadParams& p)
{
  const std::vector<double> v = parseList(s);
  if (v.size() < 2 || v.size() > 3) return false;
  p.origin_latitude = v[0];
  p.origin_longitude = v[1];
  if (v.size() == 3) p.origin_altitude = v[2];
  return true;
}

/// Reads the keys of config/prior_grid.yaml from a YAML file into @p p (absent keys keep their values).
void readYaml(const std::string& path, map_io::PriorGridParams& p)
{
  map_io::forEachPriorGridParam(p, map_io::yamlReader(map_io::loadYamlFile(path)));
}

double seconds(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b)
{
  return std::chrono::duration<double>(b - a).count();
}

}  // namespace

int main(int argc, char** argv)
{
  map_io::PriorGridParams all;
  all.resolution = kDefaultResolution;
  map_io::MapLoadParams& params = all.map;
  double& resolution = all.resolution;
  double& margin = all.margin;
  double max_cells = kDefaultMaxCells, size = 0.0;
  std::vector<double> centre{ 0.0, 0.0 };
  std::string png;
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    auto value = [&]() -> std::string { return argv[++i]; };
    auto number = [&](double& out) {
      const std::string s = value();
      char* end = nullptr;
      out = std::strtod(s.c_str(), &end);
      return end != s.c_str() && *end == '\0';
    };
    bool ok = true;
    if (a == "--help" || a == "-h")
    {
      usage(std::cout);
      return 0;
    }
    else if (a == "--metric")
      params.metric = true;
    else if (!has_value)
      ok = false;
    else if (a == "--map")
      params.file = value();
    else if (a == "--config")
    {
      try
      {
        const std::string map_file = params.file;
        readYaml(value(), all);
        if (!map_file.empty()) params.file = map_file;  // --map given before --config wins
      }
      catch (const std::exception& e)
      {
        std::cerr << "prior_grid_tool: " << e.what() << "\n";
        return kExitUsage;
      }
    }
    else if (a == "--origin")
      ok = parseOrigin(value(), params);
    else if (a == "--resolution")
      ok = number(resolution) && std::isfinite(resolution) && resolution > 0.0;
    else if (a == "--margin")
      ok = number(margin) && std::isfinite(margin) && margin >= 0.0;
    else if (a == "--max-cells")
      ok = number(max_cells) && std::isfinite(max_cells) && max_cells >= 1.0;
    else if (a == "--size")
      ok = number(size) && std::isfinite(size) && size > 0.0;
    else if (a == "--centre")
    {
      centre = parseList(value());
      ok = centre.size() == 2;
    }
    else if (a == "--png")
      png = value();
    else if (a == "--source")
    {
      try
      {
        params.source = map_io::parseMapSourceKind(value());
      }
      catch (const core::ParameterError& e)
      {
        std::cerr << "prior_grid_tool: " << e.what() << "\n";
        return kExitUsage;
      }
    }
    else
      ok = false;
    if (!ok)
    {
      std::cerr << "prior_grid_tool: bad or incomplete option '" << a << "'\n";
      usage(std::cerr);
      return kExitUsage;
    }
  }
  if (params.file.empty())
  {
    usage(std::cerr);
    return kExitUsage;
  }

  try
  {
    core::requirePositive("resolution", resolution);
    all.beta.validate();
    const auto t0 = std::chrono::steady_clock::now();
    map_io::MapLoadReport report;
    const core::VectorMap map = map_io::loadVectorMap(params, &report);
    const auto t1 = std::chrono::steady_clock::now();
    std::cout << map_io::summary(report) << "\n";
    for (const auto& m : report.messages) std::cout << "  skipped " << m << "\n";

    core::GridGeometry extent = core::PriorGrid::extentOf(map, resolution, margin);
    if (size > 0.0)
    {
      map_io::PriorGridParams window_params;
      window_params.publish_size = size;
      window_params.publish_centre_x = centre[0];
      window_params.publish_centre_y = centre[1];
      window_params.max_published_cells = max_cells;
      bool cropped = false;
      extent = map_io::publishedWindow(extent, window_params, cropped);
    }
    if (static_cast<double>(extent.numCells()) > max_cells)
    {
      std::cerr << "prior_grid_tool: the map's extent (" << extent.sizeX() << " m x " << extent.sizeY() << " m) is "
                << extent.numCells() << " cells at " << resolution
                << " m, more than --max-cells; use a coarser --resolution\n";
      return 1;
    }
    core::PriorBuildStats stats;
    core::PriorGrid grid;
    grid.build(map, extent, &stats);
    const auto t2 = std::chrono::steady_clock::now();
    const core::PriorClassCounts n = grid.classCounts();
    const auto& g = grid.geometry();
    std::cout << "grid: " << g.width << " x " << g.height << " cells of " << g.resolution << " m, origin ("
              << g.origin_x << ", " << g.origin_y << "), " << grid.bytes() << " bytes ("
              << static_cast<double>(grid.bytes()) / static_cast<double>(g.numCells()) << " byte/cell)\n"
              << "buildings: " << map.buildings.size() << " (" << stats.buildings_rasterised << " rasterised, "
              << stats.buildings_empty << " cover no cell centre, " << stats.buildings_outside
              << " outside the grid)\n"
              << "roads: " << map.road_areas.size() << " areas, " << map.road_lines.size() << " centre lines\n"
              << "skipped geometries: " << report.skipped_geometries << " while loading, " << stats.skipped_invalid
              << " while rasterising\n"
              << "cells: building " << n[static_cast<int>(core::PriorClass::kBuilding)] << ", road "
              << n[static_cast<int>(core::PriorClass::kRoad)] << ", other "
              << n[static_cast<int>(core::PriorClass::kOther)] << "\n"
              << "time: load+project " << seconds(t0, t1) << " s, rasterise " << seconds(t1, t2) << " s\n";
    if (!png.empty())
    {
      map_io::writePriorPng(grid, png);
      std::cout << "wrote " << png << "\n";
    }
  }
  catch (const std::exception& e)
  {
    std::cerr << "prior_grid_tool: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
