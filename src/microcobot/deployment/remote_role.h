#pragma once
/// @file
/// A distributed platform's far end as this process sees it: the master process drives the slave
/// stage as remote devices (net::RemoteSlave), the slave process takes its commands from the remote
/// master (net::RemoteMaster, a live::RemoteLink).

#include <memory>

#include "microcobot/deployment/serve_config.h"
#include "microcobot/live/live_platform.h"
#include "microcobot/net/microscope_link.h"
#include "microcobot/net/remote_master.h"
#include "microcobot/net/remote_slave.h"

namespace mc::deployment {

/// The DDS end of this process's role: `slave` in the master role, `master` in the slave role,
/// neither in the single role.
struct RemoteEnds {
  std::unique_ptr<net::RemoteSlave> slave;
  std::unique_ptr<net::RemoteMaster> master;
};

/// Starts the DDS end of `config.role` and points `lp` at it: in the master role the stage,
/// rotary axis, gripper and camera of each scene are the slave process's (`lp.make_devices`); in
/// the slave role the commands come from the remote master (`lp.remote`). The ends must outlive
/// the live platform built from `lp`. Throws mc::UsageError naming the flag of a link field given
/// without a link (single role) or out of range, mc::Error from DDS.
RemoteEnds attach_role(const ServeConfig& config, live::LiveParams& lp);

/// The live platform's focus drive as the microscope topics carry it: where the focal plane is,
/// or (`wanted`) where its operator sent it. Nothing (no focus) before the loop has run.
net::MicroscopeJoints microscope_joints(const live::LivePlatform& live, bool wanted);

}  // namespace mc::deployment
