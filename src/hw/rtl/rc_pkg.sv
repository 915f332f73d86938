// rc_pkg.sv — constants and types shared by the modules of a raster core (raster_core.sv,
// rc_vertex_stage.sv): the memories' row stride and the triangle FIFO entry, which the vertex
// stage's face setup writes and the pixel stage's generator reads.
package rc_pkg;
  localparam int KW = 200;  // kMaxWindow: row stride of the window memories (y·200 + x)

  // One front-facing triangle with a non-empty clipped box (src/hw/rtl/README.md, "Triangle
  // FIFO"): the box relative to the window (x_lo, x_hi, y_lo, y_hi) and the memory address of
  // its first pixel, the edge functions E_k at that pixel (ap_int<50> F16), their steps A_k, B_k
  // (ap_int<24>), the owned-edge minima (min_e ∈ {0, 1}), the shift sh and the corners' 1/W
  // (F26).
  typedef struct packed {
    logic [7:0]  xlo, xhi, ylo, yhi;
    logic [15:0] addr0;
    logic [2:0][49:0] e;
    logic [2:0][23:0] a, b;
    logic [2:0]  mine;
    logic [4:0]  sh;
    logic [2:0][31:0] iz;
  } tri_t;
  localparam int TRI_W = 4 * 8 + 16 + 3 * 50 + 2 * 3 * 24 + 3 + 5 + 3 * 32;  // 446 bits
endpackage
