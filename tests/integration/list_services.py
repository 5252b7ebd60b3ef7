#!/usr/bin/python3
"""Prints the services a gRPC server lists through server reflection, one per line."""
import sys

import grpc

import reflection_v1alpha_pb2 as pb
import reflection_v1alpha_pb2_grpc as pb_grpc


def main():
    with grpc.insecure_channel(sys.argv[1]) as channel:
        stub = pb_grpc.ServerReflectionStub(channel)
        try:
            for response in stub.ServerReflectionInfo(iter([pb.ServerReflectionRequest(list_services="")])):
                for service in response.list_services_response.service:
                    print(service.name)
        except grpc.RpcError as e:
            print(f"{e.code().name}: {e.details()}", file=sys.stderr)
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
