#!/usr/bin/env bash
# mpirun recipes (not run by the tests).
# Laptop, 2 cores:
#   mpirun -np 2 partet mesh model.off -o out/model --pieces 2
# More pieces than ranks (less memory per piece):
#   mpirun -np 2 partet mesh model.off -o out/model --pieces 8
# Several nodes, hostfile with slots:
#   mpirun -np 16 --hostfile hosts --map-by node partet mesh model.off -o out/model --pieces 16
# As root in a container, or more ranks than cores:
#   OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe -np 4 partet mesh ...
echo "see the comments in $0"
