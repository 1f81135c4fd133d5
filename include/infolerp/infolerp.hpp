#pragma once
// Umbrella header, for convenience only: every infolerp header compiles on its own, and a
// translation unit that includes only the headers it uses parses less.
// Convention: an entry point takes its inputs, then its options, then the executor, options and
// executor defaulted (serial_executor) where the call stays unambiguous (cluster_mesh and
// cluster_keyframes take the executor before their trailing pack of channels); a type whose
// construction can fail is made by its static `create`, which returns result<T>, and a free
// function that makes a new value is named make_<what> (make_topology, make_contraction_hierarchy).

// Entry points: what an engine calls.
#include "infolerp/cluster/cluster_mesh.hpp"             // Algorithm 1: cluster ids per triangle
#include "infolerp/saliency/mesh_saliency.hpp"           // saliency per vertex (Lee et al.)
#include "infolerp/saliency/salient_clustering.hpp"      // salient clusters, cluster-localised saliency
#include "infolerp/saliency/cluster_importance.hpp"      // view-dependent importance and budgets
#include "infolerp/lod/lod_mesh.hpp"                     // mesh -> ready LOD, frames within a triangle budget
#include "infolerp/lod/view_dependent_lod.hpp"           // per-frame saliency LOD into an index buffer
#include "infolerp/refine/progressive_driver.hpp"        // progressive refinement (NLD_OS, NLD_IS, RND)
#include "infolerp/upsample/upsampler.hpp"               // the I-Buffer upsampler
#include "infolerp/upsample/pass_controller.hpp"         // automatic pass count
#include "infolerp/upsample/frame_reuse.hpp"             // reuse across the frames of a camera path
#include "infolerp/cluster/uv_seams.hpp"                 // clusters cut at texture seams
#include "infolerp/mesh/validate.hpp"                    // mesh checks
#include "infolerp/mesh/locality_order.hpp"              // Morton order of triangles

// What you implement (or adapt): mesh, tracer, job system, sample source.
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/tracer.hpp"
#include "infolerp/core/executor.hpp"
#include "infolerp/upsample/sample_source.hpp"
#include "infolerp/upsample/ray_cast_source.hpp"          // a ready sample source over your tracer
#include "infolerp/mesh/adaptors.hpp"                    // ready mesh types and views

// Building blocks: channels, one-channel clustering, information theory, geometry, refinement.
#include "infolerp/cluster/channel.hpp"
#include "infolerp/cluster/visibility_channel.hpp"
#include "infolerp/cluster/visibility_images.hpp"
#include "infolerp/cluster/orientation_channel.hpp"
#include "infolerp/cluster/stretch_channel.hpp"
#include "infolerp/cluster/region_growing.hpp"
#include "infolerp/cluster/boundary_smoothing.hpp"
#include "infolerp/info/entropy.hpp"
#include "infolerp/info/jensen_shannon.hpp"
#include "infolerp/info/js_estimate.hpp"
#include "infolerp/info/log2.hpp"
#include "infolerp/mesh/curvature.hpp"
#include "infolerp/mesh/geometry.hpp"
#include "infolerp/mesh/topology.hpp"
#include "infolerp/refine/criteria.hpp"
#include "infolerp/refine/nld.hpp"
#include "infolerp/refine/nld_os_queue.hpp"
#include "infolerp/refine/pinhole_camera.hpp"
#include "infolerp/refine/refiner_types.hpp"
#include "infolerp/refine/subdivision_mesh.hpp"
#include "infolerp/lod/weighting_map.hpp"
#include "infolerp/lod/contraction_hierarchy.hpp"
#include "infolerp/lod/view_selection.hpp"
#include "infolerp/lod/screen_error_selection.hpp"
#include "infolerp/lod/hidden_triangles.hpp"
#include "infolerp/lod/vertex_contraction.hpp"
#include "infolerp/lod/cluster_split.hpp"
#include "infolerp/lod/cluster_local_indices.hpp"
#include "infolerp/mesh/support_function.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/core/random.hpp"
#include "infolerp/core/unit_vector.hpp"
#include "infolerp/core/large_buffer.hpp"
