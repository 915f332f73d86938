// axi_record_writer.sv — the output buffer of the weighing accelerator (weigh_accel.sv): takes
// `count` records of RB = 4·DW bits (64 bytes at DW = 128) from a valid/ready stream and writes
// record k to base + k·64 in DDR, one INCR burst of 4 DW-bit beats per record (AW, then its four
// W beats, then the next record; write responses are counted as they come, several may be
// outstanding). base must be 256-byte aligned (records never cross a 4 KB boundary). done: every
// record's write response (OKAY or not) has come back; bresp_err: one was not OKAY.
module axi_record_writer #(
    parameter int DW = 128,  // AXI data bits
    parameter int ID = 0     // AWID
) (
    input  logic            clk,
    input  logic            rst,
    input  logic            start,       // one clock: a call begins; base and count are sampled
    input  logic [63:0]     base,
    input  logic [9:0]      count,       // records of the call
    output logic            done,
    output logic            bresp_err,   // a write response of the call was not OKAY
    // Records.
    input  logic            rec_valid,
    output logic            rec_ready,
    input  logic [4*DW-1:0] rec_data,
    // AXI4 write channels.
    output logic            awvalid,
    input  logic            awready,
    output logic [63:0]     awaddr,
    output logic [7:0]      awlen,
    output logic [2:0]      awid,
    output logic            wvalid,
    input  logic            wready,
    output logic [DW-1:0]   wdata,
    output logic            wlast,
    input  logic            bvalid,
    input  logic [1:0]      bresp
);
  // States (one-hot): EMPTY (waiting for a record) → AW (address) → W (four beats) → EMPTY.
  localparam int S_EMPTY = 0, S_AW = 1, S_W = 2;
  logic [2:0]       st;
  logic [4*DW-1:0]  rec;
  logic [1:0]       beat;
  logic [63:0]      addr;
  logic [9:0]       recs_left, resp_left;

  assign rec_ready = st[S_EMPTY] && recs_left != 0;
  assign awvalid   = st[S_AW];
  assign awaddr    = addr;
  assign awlen     = 8'd3;
  assign awid      = 3'(ID);
  assign wvalid    = st[S_W];
  assign wdata     = rec[beat*DW+:DW];
  assign wlast     = beat == 2'd3;
  assign done      = recs_left == 0 && resp_left == 0 && st[S_EMPTY];

  always_ff @(posedge clk) begin
    if (rst) begin
      st <= 3'b001;
      beat <= '0;
      addr <= '0;
      recs_left <= '0;
      resp_left <= '0;
      bresp_err <= 1'b0;
    end else begin
      if (start) begin
        addr <= base;
        recs_left <= count;
        resp_left <= count;
        bresp_err <= 1'b0;
      end else begin
        if (bvalid) begin
          resp_left <= resp_left - 10'd1;
          if (bresp != 2'b00) bresp_err <= 1'b1;
        end
        unique case (1'b1)
          st[S_EMPTY]:
            if (rec_valid && rec_ready) begin
              rec <= rec_data;
              recs_left <= recs_left - 10'd1;
              st <= 3'b010;
            end
          st[S_AW]:
            if (awready) begin
              beat <= '0;
              st <= 3'b100;
            end
          st[S_W]:
            if (wready) begin
              beat <= beat + 2'd1;
              if (wlast) begin
                addr <= addr + 64'd64;
                st <= 3'b001;
              end
            end
          default: ;
        endcase
      end
    end
  end

`ifndef SYNTHESIS
  logic hs_aw_wait, hs_w_wait;
  logic [63:0] hs_awaddr;
  logic [DW:0] hs_w;
  always_ff @(posedge clk) begin
    hs_aw_wait <= !rst && awvalid && !awready;
    hs_w_wait <= !rst && wvalid && !wready;
    hs_awaddr <= awaddr;
    hs_w <= {wlast, wdata};
    if (!rst) begin
      assert ($onehot(st))
      else $error("axi_record_writer: state %b is not one-hot", st);
      if (hs_aw_wait)
        assert (awvalid && awaddr == hs_awaddr)
        else $error("axi_record_writer: awvalid dropped or awaddr changed before awready");
      if (hs_w_wait)
        assert (wvalid && {wlast, wdata} == hs_w)
        else $error("axi_record_writer: wvalid dropped or the W beat changed before wready");
      assert (!(bvalid && resp_left == 0))
      else $error("axi_record_writer: a write response with none outstanding");
      assert (!(start && !done && (recs_left != 0 || resp_left != 0)))
      else $error("axi_record_writer: start while a call is running");
      assert (!start || base[7:0] == 8'd0)
      else $error("axi_record_writer: base 0x%0h not 256-byte aligned", base);
    end
  end
`endif
endmodule
