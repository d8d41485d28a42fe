#pragma once
/// @file
/// A camera frame as a baseline TIFF 6.0 file (Adobe, TIFF Revision 6.0, 1992: Part 1, "Baseline
/// TIFF"): little-endian, one uncompressed strip, grey (BlackIsZero), 8 bits per sample for
/// 8-bit frames and 16 otherwise (values as they are: a 12-bit frame spans 0..4095, and
/// MaxSampleValue says so). The object-side pixel size goes into XResolution/YResolution in
/// pixels per centimetre (ResolutionUnit 3), which ImageJ/Fiji read as the image's scale, and the
/// camera's state into ImageDescription (one line of JSON). Microscopy software reads 16-bit
/// TIFF where PNG readers often do not; no compression, so any reader opens it.

#include <string>

#include "microcobot/imaging/sensor_model.h"

namespace mc::imaging {

/// The TIFF bytes of `frame`; `m_per_px` > 0 sets the resolution tags (object side), and
/// `description` (ASCII, no NUL) the ImageDescription tag when not empty. Throws InvalidParams
/// on an empty frame, a non-finite scale or a description that is not printable ASCII.
std::string encode_tiff(const Frame& frame, double m_per_px, const std::string& description);

}  // namespace mc::imaging
