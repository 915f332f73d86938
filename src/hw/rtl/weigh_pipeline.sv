// weigh_pipeline.sv — the render/score pipeline of one filter iteration's weighing (thesis
// §7.5.3, Fig. 7.17 [HARDWARE.md]; C model: the DistributeFT, VertexMultiplier, DistributeDepth,
// RasterCore × M and MergeWeights processes of HwWeighTop<M>, src/hw/top.h) as RTL:
//
//   ft ──▶ ft_distributor ──────────────┐
//   model ─▶ vertex_multiplier ─────────┤  per core c: window, pixels, FT, vertices
//   img, win ─▶ depth_distributor ──────┤
//                                       ▼
//                          raster_core × M ──▶ weight_merger ──▶ out (weight, index, stats)
//                                     prob, cell ─┘
//
// M (a parameter, 1 … 10; the thesis's designs are 5 and 10) raster cores; particle p of a
// call is rendered by core p mod M. Every stream is valid/ready (AXI4-Stream rules), inside and
// outside. A call (num_particles particles, one mesh) takes on its inputs:
//   img    img_width·img_height depth pixels (depth_t raw F10 m), row-major;
//   win    one window per particle (u0, v0, width, height), inside the image;
//   ft     12 FT elements per particle (ft_t raw F22, row-major 3 × 4);
//   model  1024 vertex words {x, y, z} (xyz_t raw F10 m, 13 bits each), then num_faces face
//          words (three 10-bit vertex indices);
//   prob   kNumCells = 6300 class probabilities (prob_t raw F8);
//   cell   one cell index per particle;
// and gives one output word per particle, in particle order. The processes upstream of these
// streams (sample info, FT chain, the bursts from DDR) and downstream (sorter, statistics) are
// the C model's HLS kernels (src/hw/top.h). Parameters (prm_*, num_*, img_*) are the raw words
// of WeighConfig's fields and must be stable during a call.
module weigh_pipeline #(
    parameter int M   = 5,
    parameter int VFD = 2048  // the vertex multiplier's per-core vertex FIFO (block RAM) entries
) (
    input  logic         clk,
    input  logic         rst,
    input  logic [9:0]   num_particles,    // n ≤ 510
    input  logic [11:0]  num_faces,        // ≤ 2048
    input  logic [9:0]   img_width,        // ≤ 640
    input  logic [9:0]   img_height,       // ≤ 480
    // RasterParams (raw).
    input  logic         prm_zbuffer,
    input  logic         prm_hard,
    input  logic [23:0]  prm_thr1,         // F20 m
    input  logic [19:0]  prm_inv_thr1,     // F8 1/m
    input  logic [23:0]  prm_hard_thr,     // F20 m
    input  logic [23:0]  prm_align_band,   // F20 m
    input  logic [23:0]  prm_edge_band,    // F20 m
    input  logic [23:0]  prm_near_plane,   // F20 m
    // WeightParams (raw coef_t F15).
    input  logic [15:0]  prm_alpha,
    input  logic [15:0]  prm_beta,
    input  logic [15:0]  prm_gamma,
    input  logic [15:0]  prm_delta,
    input  logic         prm_occlusion_aware,
    // Input streams.
    input  logic         img_valid,
    output logic         img_ready,
    input  logic [11:0]  img_data,
    input  logic         win_valid,
    output logic         win_ready,
    input  logic [9:0]   win_u0,
    input  logic [9:0]   win_v0,
    input  logic [7:0]   win_width,
    input  logic [7:0]   win_height,
    input  logic         ft_valid,
    output logic         ft_ready,
    input  logic [35:0]  ft_data,
    input  logic         model_valid,
    output logic         model_ready,
    input  logic [38:0]  model_data,
    input  logic         prob_valid,
    output logic         prob_ready,
    input  logic [7:0]   prob_data,
    input  logic         cell_valid,
    output logic         cell_ready,
    input  logic [12:0]  cell_data,
    // Output stream.
    output logic         out_valid,
    input  logic         out_ready,
    output logic [17:0]  out_weight,       // weight_t raw F17
    output logic [9:0]   out_index,        // particle index in the call
    output logic [313:0] out_stats,        // RasterCoreOutput (weight_merger.sv lists the fields)
    // DepthDistributionCounts of the last call.
    output logic [31:0]  dd_reads_shared,
    output logic [31:0]  dd_reads_unshared
);
  logic [M-1:0]     info_valid, info_ready, depth_valid, depth_ready, ftc_valid, ftc_ready;
  logic [M-1:0]     vert_valid, vert_ready, core_valid, core_ready;
  logic [M*36-1:0]  info_data;
  logic [M*12-1:0]  depth_data;
  logic [35:0]      ftc_data;
  logic [M*39-1:0]  vert_data;
  logic [M*314-1:0] core_data;

  ft_distributor #(.M(M)) u_ftd (
      .clk, .rst, .num_particles, .ft_valid, .ft_ready, .ft_data,
      .core_valid(ftc_valid), .core_ready(ftc_ready), .core_data(ftc_data));

  vertex_multiplier #(.M(M), .FD(VFD)) u_vm (
      .clk, .rst, .num_particles, .num_faces, .model_valid, .model_ready, .model_data,
      .vert_valid, .vert_ready, .vert_data);

  depth_distributor #(.M(M)) u_dd (
      .clk, .rst, .num_particles, .img_width, .img_height, .img_valid, .img_ready, .img_data,
      .win_valid, .win_ready, .win_u0, .win_v0, .win_width, .win_height,
      .info_valid, .info_ready, .info_data, .depth_valid, .depth_ready, .depth_data,
      .reads_shared(dd_reads_shared), .reads_unshared(dd_reads_unshared));

  for (genvar c = 0; c < M; c++) begin : g_core
    raster_core u_core (
        .clk, .rst, .prm_zbuffer, .prm_hard, .prm_thr1, .prm_inv_thr1, .prm_hard_thr,
        .prm_align_band, .prm_edge_band, .prm_near_plane, .num_faces,
        .win_valid(info_valid[c]), .win_ready(info_ready[c]),
        .win_u0(info_data[36*c+26+:10]), .win_v0(info_data[36*c+16+:10]),
        .win_width(info_data[36*c+8+:8]), .win_height(info_data[36*c+:8]),
        .depth_valid(depth_valid[c]), .depth_ready(depth_ready[c]), .depth_data(depth_data[12*c+:12]),
        .ft_valid(ftc_valid[c]), .ft_ready(ftc_ready[c]), .ft_data(ftc_data),
        .vert_valid(vert_valid[c]), .vert_ready(vert_ready[c]),
        .vert_x(vert_data[39*c+26+:13]), .vert_y(vert_data[39*c+13+:13]), .vert_z(vert_data[39*c+:13]),
        .out_valid(core_valid[c]), .out_ready(core_ready[c]),
        .out_inlier_sum(core_data[314*c+272+:42]), .out_n_raster(core_data[314*c+240+:32]),
        .out_n_occluded(core_data[314*c+208+:32]), .out_n_depth(core_data[314*c+176+:32]),
        .out_depth_diff_sum(core_data[314*c+120+:56]), .out_depth_diff_count(core_data[314*c+88+:32]),
        .out_n_edge(core_data[314*c+56+:32]), .out_n_edge_continued(core_data[314*c+24+:32]),
        .out_faces_front(core_data[314*c+12+:12]), .out_faces_total(core_data[314*c+:12]));
  end

  weight_merger #(.M(M)) u_wm (
      .clk, .rst, .num_particles, .prm_alpha, .prm_beta, .prm_gamma, .prm_delta, .prm_occlusion_aware,
      .prob_valid, .prob_ready, .prob_data, .cell_valid, .cell_ready, .cell_data,
      .core_valid, .core_ready, .core_data, .out_valid, .out_ready, .out_weight, .out_index, .out_stats);

`ifndef SYNTHESIS
  // M within 1 … 10 (kMaxRasterCores: the core counters are 4 bits).
  initial assert (M >= 1 && M <= 10) else $fatal(1, "weigh_pipeline: M = %0d outside 1 … 10", M);
`endif
endmodule
