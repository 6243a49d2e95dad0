// Video files from rendered frames, through the `ffmpeg` program when it is installed.
#pragma once

#include <filesystem>
#include <optional>
#include <string_view>
#include <vector>

#include "core/result.h"

namespace wrap::render {

/// The executable `name` found on PATH, or nothing.
std::optional<std::filesystem::path> FindProgram(std::string_view name);

/// Fails with kInvalidInput saying that ffmpeg is not installed (and how to get it) when it is
/// not on PATH; succeeds otherwise.
Result<void> CheckVideoEncoder();

/// Encodes PNG `frames` into an H.264 MP4 `output`, frame i shown for `durations_s[i]` seconds
/// (30 frames per second), through ffmpeg's concat demuxer. Its log goes to `output` + ".log"
/// and is removed on success. Fails with kInvalidInput when ffmpeg is not installed, kIo when it
/// fails (its last log lines in the message).
Result<void> EncodeVideo(const std::vector<std::filesystem::path>& frames,
                         const std::vector<double>& durations_s,
                         const std::filesystem::path& output);

}  // namespace wrap::render
