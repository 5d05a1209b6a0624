// Subcommands of the `adit` tool; each file registers one on the CLI11 app.
#pragma once

#include <CLI/CLI.hpp>

#include <string>

void registerImportCommand(CLI::App& app);
void registerInfoCommand(CLI::App& app);
void registerConfigCommand(CLI::App& app);
void registerSimCommand(CLI::App& app);
void registerReplayCommand(CLI::App& app);
void registerLaunchCommand(CLI::App& app);
void registerSpyCommand(CLI::App& app);
void registerEvalCommand(CLI::App& app);
void registerCommandCommand(CLI::App& app);
void registerExportCommand(CLI::App& app);
void registerViewCommand(CLI::App& app);

void registerDemoCommand(CLI::App& app);
void registerBenchCommand(CLI::App& app);

// Folder of the running executable (build/bin), to find sibling programs and build/share.
std::string executableDir();
// A progress bar on stderr (call with 0..1; 1 ends the line).
void drawProgress(double fraction);
// Exit status of `adit info` / `adit replay` when the input log was damaged (corrupt frames, truncated),
// and of `adit import rosbag` / `adit info` for a bag with lost chunks: the readable part was used, but the
// result is not the whole input's.
constexpr int kExitDamagedInput = 3;
