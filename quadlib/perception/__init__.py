"""Perception for navigation without GPS: a 2D lidar in a map of walls, scan matching (ICP), and a
particle filter that localises against the map from an ambiguous start."""

from .icp import IcpResult, best_rigid_transform, convergence_basin, estimate_normals, icp, point_to_plane_step
from .lidar import LidarScan, cast_rays, corridor_map, lidar_scan, room_map
from .map_matching import MapMatch, scan_to_map, track_scans, wall_points
from .particles import (
                        RESAMPLING_SCHEMES,
                        LocalisationRun,
                        effective_sample_size,
                        localise,
                        odometry_step,
                        particle_pose,
                        pose_error,
                        resample,
                        scan_log_likelihood,
)
from .range_ekf import scan_range_sensor, unicycle_model
from .scenario import LocalisationScenario, corner_start, corner_trials, hypothesis_particles
from .vo import (
                        CAMERA_IN_BODY,
                        Camera,
                        VoRun,
                        decompose_essential,
                        essential_eight_point,
                        essential_ransac,
                        observe,
                        project,
                        recover_pose,
                        relative_scale,
                        textured_room,
                        triangulate,
                        visual_odometry,
)

__all__ = ["CAMERA_IN_BODY", "Camera", "VoRun", "decompose_essential", "essential_eight_point", "essential_ransac",
           "observe", "project", "recover_pose", "relative_scale", "textured_room", "triangulate", "visual_odometry",
           "RESAMPLING_SCHEMES", "IcpResult", "LidarScan", "LocalisationRun", "LocalisationScenario", "MapMatch",
           "best_rigid_transform", "cast_rays", "convergence_basin", "corner_start", "corner_trials", "corridor_map",
           "effective_sample_size",
           "estimate_normals", "hypothesis_particles", "icp", "lidar_scan", "localise", "odometry_step",
           "particle_pose", "point_to_plane_step", "pose_error", "resample", "room_map", "scan_log_likelihood",
           "scan_range_sensor", "scan_to_map", "track_scans", "unicycle_model", "wall_points"]
