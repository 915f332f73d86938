"""posefilter: robust 6-DoF object pose estimation with a rendering particle filter.

The compiled core is ``posefilter._posefilter`` (pybind11, built by CMake); this package
re-exports it. Plots live in :mod:`posefilter.plots` (needs matplotlib). See docs/PYTHON.md.

Conventions: metres and radians; depth arrays are H x W camera z (0 = missing); 4x4 poses map
object -> camera (T_cam_obj); 6-vector poses are (x, y, z, roll, pitch, yaw), object -> base.
"""

from ._posefilter import (  # noqa: F401
    BatchResult,
    Camera,
    Detection,
    Error,
    Estimator,
    Mesh,
    PoseErrors,
    Prior,
    PyramidLayout,
    Result,
    SynthScene,
    TrackResult,
    Tracker,
    add_error,
    adds_error,
    dataset_targets,
    detections_to_raw_pyramid,
    draw_pose_overlay,
    load_depth_png,
    load_mesh,
    load_rgb_png,
    make_box,
    make_cylinder,
    make_lshape,
    make_shape,
    make_synth_scene,
    make_synth_sequence,
    make_torus,
    pose_errors,
    pose_to_transform,
    post_process_pyramid,
    prior_from_detections,
    projected_box,
    read_camera_json,
    read_detections_json,
    read_gt_json,
    read_raw_pyramid,
    read_results_json,
    read_xyz_points,
    render_depth,
    run_dataset,
    rotation_error_deg,
    sample_cells,
    sample_points,
    save_depth_png,
    save_rgb_png,
    shade_depth,
    synth_class_names,
    synth_option_names,
    transform_to_pose,
    translation_error,
    uniform_prior,
    wrap_angle,
    write_camera_json,
    write_detections_json,
    write_synth_sequence,
    write_gt_json,
    ycbv_class_names,
)

from ._posefilter import __version__  # the C++ build's version (posefilter/version.h)
from ._posefilter import __git_revision__  # the commit it was built from, "unknown" outside git

__all__ = [name for name in dir() if not name.startswith("_")]
