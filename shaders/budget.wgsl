// The work of one invocation is bounded: every loop iteration is charged to
// `iterations` (a polygon test by its vertex count), and a traversal (traverse.wgsl)
// that would pass frame.iteration_budget stops between two steps with its state
// (current node, leaf cursor, best hit, stack depth) saved in its TraceRay and its
// stack in `traversal_stack`; the next dispatch resumes it. llvmpipe ends every loop of an
// invocation once the vector of invocations it runs together has made 65,535 loop
// iterations in all (LP_MAX_TGSI_LOOP_ITERATIONS in Mesa's gallivm). A vector iterates
// only while one of its lanes does, so its count is at most the sum of its lanes'
// counts: the host gives each lane the limit divided by the lanes per vector. A loop
// that ends without reaching one of its exits was cut by the driver all the same: that
// sets ERROR_LOOP_CUT for the host, which then refuses the image.

// Loop iterations this invocation has run.
var<private> iterations: u32;
