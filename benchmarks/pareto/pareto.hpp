#pragma once
// Subcommands of build/benchmarks/infolerp_pareto, one per file benchmarks/pareto/<sub>.cpp.
// Declared weak so the binary links while only some of them exist; main() skips absent ones.
[[gnu::weak]] int pareto_refine(int argc, char** argv);    // refine.cpp: NLD_OS / NLD_IS / RND (issue 5)
[[gnu::weak]] int pareto_upsample(int argc, char** argv);  // upsample.cpp: I-Buffer upsampler
