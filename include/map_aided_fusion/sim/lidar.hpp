/**
 * @file lidar.hpp
 * @brief Lidar models: beam elevations, azimuth sampling, range limits and noise, with presets for the
 *        paper's 4-layer IBEO Alaska XT and for 32/64-beam spinning lidars.
 *
 * The lidar frame is mounted on base_link at (x, y, z, yaw), level with the vehicle's body. By default all rays
 * of a scan are cast from the pose of the scan's time stamp; with `rolling_sweep` each azimuth fires at its own
 * time over the scan period, from the ego's pose at that time (a real spinning lidar's motion distortion).
 */
#pragma once

#include <string>
#include <vector>

namespace map_aided_fusion {
namespace sim {

/// A lidar model. Angles in degrees, distances in metres.
struct LidarParams
{
  std::string preset = "vlp32";
  /// Beam elevations, ascending (ring 0 = lowest beam), degrees in (-89, 89).
  std::vector<double> elevations_deg;
  double azimuth_resolution_deg = 0.2;  ///< step between two firings of a beam (> 0)
  double fov_deg = 360.0;               ///< horizontal field of view, centred on the lidar's +x axis, (0, 360]
  double min_range = 0.5;               ///< returns closer than this are discarded
  double max_range = 100.0;             ///< no return beyond
  double range_noise_stddev = 0.02;     ///< Gaussian noise on the range of each return
  double dropout_probability = 0.02;    ///< probability that a return is lost, [0, 1)
  double rate_hz = 10.0;                ///< scans per second
  double mount_x = 1.2;                 ///< lidar position on base_link
  double mount_y = 0.0;
  double mount_z = 1.9;
  double mount_yaw_deg = 0.0;
  /**
   * Firing i of n (azimuth order) at i / n of the scan period after the scan's stamp, from the ego's pose then;
   * each point is in the lidar frame of its own firing and carries its time (ScanFrame, the bag's `time` field).
   * Objects stay where they are at the stamp.
   */
  bool rolling_sweep = false;

  /// Number of azimuths of a scan (fov / resolution, + 1 when the fov is not a full turn).
  int numAzimuths() const;
  /// Azimuth (degrees, lidar frame) of firing @p i.
  double azimuthDeg(int i) const;
  int numBeams() const { return static_cast<int>(elevations_deg.size()); }

  /// @throws core::ParameterError naming the parameter ("lidar.<name>")
  void validate() const;

  /**
   * @brief A preset by name:
   * - `ibeo4`: the paper's IBEO Alaska XT, 4 layers at -1.2, -0.4, +0.4, +1.2 deg (0.8 deg apart, 3.2 deg
   *   aperture with the beam width), 0.5 deg azimuth steps over a 110 deg forward field of view: 221 × 4 =
   *   884 rays, about 800 returns per scan in a street; front bumper mount (x 3.7 m, z 0.5 m), max 80 m.
   * - `vlp32`: Velodyne VLP-32C, 32 beams from -25 to +15 deg (denser near the horizon), 0.2 deg over 360 deg
   *   (57 600 rays), roof mount (x 1.2 m, z 1.9 m), max range 100 m (the sensor's 200 m is never reached in a
   *   town).
   * - `hdl32`: Velodyne HDL-32E (the nuScenes lidar), 32 beams from -30.67 to +10.67 deg every 4/3 deg,
   *   0.16 deg over 360 deg (72 000 rays), mount as on the nuScenes car (x 0.94 m, z 1.84 m), max range 100 m.
   * - `hdl64`: Velodyne HDL-64E, 64 beams from -24.33 to +2 deg, 0.18 deg over 360 deg (128 000 rays), roof
   *   mount, max range 120 m.
   * @throws core::ParameterError for an unknown name.
   */
  static LidarParams fromPreset(const std::string& name);
};

/// Names of the presets.
std::vector<std::string> lidarPresetNames();

}  // namespace sim
}  // namespace map_aided_fusion
