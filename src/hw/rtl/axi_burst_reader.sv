// axi_burst_reader.sv — one input buffer of the weighing accelerator (weigh_accel.sv): reads
// `count` elements of EB bytes, packed back to back from byte address `base` in DDR, with AXI4
// read bursts, and gives them as a valid/ready element stream (AXI4-Stream rules).
//
// Bursts: INCR, DW-bit beats (DW/8 bytes), up to 16 beats (256 bytes) each; base must be
// 256-byte aligned, so no burst crosses a 4 KB boundary. A burst is requested (ar_req, taken by
// the top's arbiter with ar_grant) only when the beat FIFO has room for all of its beats counted
// with those still in flight, so read data of this reader's ID is always accepted (the top holds
// RREADY at 1 and never blocks another reader's data).
// Gearbox: beats leave the FIFO into a 2·DW-bit byte buffer (gbuf, nb valid bytes, the oldest at
// bit 0); an element is its lowest EB bytes, so elements may straddle beats (EB = 6: a window).
// Bytes of the last beat past count·EB are dropped. The element word is a register (stable
// while out_valid waits for out_ready).
module axi_burst_reader #(
    parameter int EB = 2,    // bytes per element, 1 … 16
    parameter int DW = 128,  // AXI data bits
    parameter int FD = 32    // beat FIFO entries (≥ 16, a power of two)
) (
    input  logic            clk,
    input  logic            rst,
    input  logic            start,     // one clock: a call begins; base and count are sampled
    input  logic [63:0]     base,      // byte address, 256-byte aligned
    input  logic [19:0]     count,     // elements of the call
    output logic            done,      // every element of the call has left (until the next start)
    // Burst requests (to the top's AR arbiter).
    output logic            ar_req,
    output logic [63:0]     ar_addr,
    output logic [7:0]      ar_len,    // beats − 1
    input  logic            ar_grant,  // the request is taken at this clock edge
    // Read data beats of this reader's ID.
    input  logic            r_valid,
    input  logic [DW-1:0]   r_data,
    // Elements.
    output logic            out_valid,
    input  logic            out_ready,
    output logic [EB*8-1:0] out_data
);
  localparam int BB = DW / 8;  // bytes per beat
  localparam int FAW = $clog2(FD);
  localparam int NBW = $clog2(2 * BB) + 1;

  logic [19:0]      elems_left;   // elements still to give
  logic [23:0]      beats_left;   // beats still to request
  logic [63:0]      next_addr;
  logic [FAW:0]     reserved;     // beats requested and not yet out of the FIFO
  logic [DW-1:0]    fifo[FD];
  logic [FAW-1:0]   wp, rp;
  logic [FAW:0]     fcnt;
  logic [2*DW-1:0]  gbuf;         // bytes 0 … nb − 1 valid, the bits above them 0
  logic [NBW-1:0]   nb;

  wire [4:0] burst = beats_left >= 24'd16 ? 5'd16 : 5'(beats_left);
  assign ar_req  = beats_left != 0 && reserved <= (FAW + 1)'(FD - 16);
  assign ar_addr = next_addr;
  assign ar_len  = 8'(burst - 5'd1);

  assign out_valid = elems_left != 0 && nb >= NBW'(EB);
  assign out_data  = gbuf[EB*8-1:0];
  assign done      = elems_left == 0 && beats_left == 0;

  wire              take = out_valid && out_ready;
  wire [NBW-1:0]    nb_after = take ? nb - NBW'(EB) : nb;
  wire [2*DW-1:0]   g_after = take ? gbuf >> (EB * 8) : gbuf;
  wire              pop = fcnt != 0 && nb_after <= NBW'(BB);
  wire [2*DW-1:0]   beat_at = {{DW{1'b0}}, fifo[rp]} << (nb_after * 8);

  always_ff @(posedge clk) begin
    if (r_valid) fifo[wp] <= r_data;
    if (rst) begin
      elems_left <= '0;
      beats_left <= '0;
      next_addr  <= '0;
      reserved   <= '0;
      wp <= '0;
      rp <= '0;
      fcnt <= '0;
      gbuf <= '0;
      nb <= '0;
    end else begin
      if (start) begin
        elems_left <= count;
        beats_left <= (24'(count) * 24'(EB) + 24'(BB - 1)) / 24'(BB);
        next_addr  <= base;
        gbuf <= '0;
        nb <= '0;
      end else begin
        if (take) elems_left <= elems_left - 20'd1;
        if (ar_grant) begin
          beats_left <= beats_left - 24'(burst);
          next_addr  <= next_addr + 64'(burst) * 64'(BB);
        end
        gbuf <= pop ? (g_after | beat_at) : g_after;
        nb   <= pop ? nb_after + NBW'(BB) : nb_after;
      end
      reserved <= reserved + (ar_grant ? (FAW + 1)'(burst) : '0) - (pop ? (FAW + 1)'(1) : '0);
      if (r_valid) wp <= wp + 1'b1;
      if (pop) rp <= rp + 1'b1;
      fcnt <= fcnt + (r_valid ? 1 : 0) - (pop ? 1 : 0);
    end
  end

`ifndef SYNTHESIS
  // Simulation checks (Verilator --assert).
  logic hs_out_wait;
  logic [EB*8-1:0] hs_out;
  always_ff @(posedge clk) begin
    hs_out_wait <= !rst && out_valid && !out_ready;
    hs_out <= out_data;
    if (!rst) begin
      assert (!(r_valid && fcnt == (FAW + 1)'(FD)))
      else $error("axi_burst_reader(EB=%0d): read data with the beat FIFO full", EB);
      assert (reserved <= (FAW + 1)'(FD))
      else $error("axi_burst_reader(EB=%0d): %0d beats reserved in a FIFO of %0d", EB, reserved, FD);
      assert (fcnt <= reserved)
      else $error("axi_burst_reader(EB=%0d): more beats queued (%0d) than requested (%0d)", EB, fcnt, reserved);
      assert (!(start && (beats_left != 0 || elems_left != 0 || reserved != 0)))
      else $error("axi_burst_reader(EB=%0d): start while a call is running", EB);
      assert (!start || base[7:0] == 8'd0)
      else $error("axi_burst_reader(EB=%0d): base 0x%0h not 256-byte aligned", EB, base);
      assert (!(ar_grant && !ar_req))
      else $error("axi_burst_reader(EB=%0d): grant without a request", EB);
      assert (nb <= NBW'(2 * BB))
      else $error("axi_burst_reader(EB=%0d): %0d bytes in a %0d-byte gearbox", EB, nb, 2 * BB);
      if (hs_out_wait)
        assert (out_valid && out_data == hs_out)
        else $error("axi_burst_reader(EB=%0d): out_valid dropped or out_data changed before out_ready", EB);
    end
  end
`endif
endmodule
