#pragma once
// Subcommands of infolerp_pareto, the time-against-error harness: each lives in its own
// benchmarks/pareto/<sub>.cpp. Weak, so that the binary links while a subcommand's file is absent.
[[gnu::weak]] int pareto_refine(int argc, char** argv);
[[gnu::weak]] int pareto_upsample(int argc, char** argv);
[[gnu::weak]] int pareto_visibility(int argc, char** argv);
