#pragma once
// nidevo-client subcommands; each returns the process exit code.
namespace nidevo::client {

int replayCommand();
int loadCommand();
int healthCommand();
int infoCommand();

}  // namespace nidevo::client
