#!/bin/sh
# The 45 frictional contact problems of Siconos' numerics test data (the twelve of
# crates/contact/tests/data/fclib/ and 33 more), at the commit the twelve were copied from,
# into DIR (default: target/fclib45). Apache License 2.0, copyright the Siconos authors.
#     sh bench/siconos/fetch.sh [DIR]
set -eu
dir=${1:-target/fclib45}
commit=6070f0f6fcd9e12457f509211e88a1a583b811bc
base=https://raw.githubusercontent.com/siconos/siconos/$commit/numerics/src/FrictionContact/test/data
mkdir -p "$dir"
for f in BoxesStack1-i100000-32.hdf5.dat Capsules-i100-1090.dat Capsules-i100-889.dat \
    Capsules-i101-404.dat Capsules-i103-990.dat Capsules-i122-1617.dat Confeti-ex03-Fc3D-SBM.dat \
    Confeti-ex13-4contact-Fc3D-SBM.dat Confeti-ex13-Fc3D-SBM.dat FC2D_SliderCrankLagrangian00000.dat \
    FC2D_SliderCrankLagrangian00001.dat FC3D_Example1.dat FC3D_Example1_SBM.dat \
    FrictionContact3D_1c.dat FrictionContact3D_RR_1c.dat FrictionContactProblem00031.dat \
    FrictionContactProblem00071.dat FrictionContactProblem00237.dat FrictionContactProblem00374.dat \
    FrictionContactProblem00394.dat FrictionContactProblem00727.dat KaplasTower-i1061-4.hdf5.dat \
    NESpheres_10_1.dat NESpheres_30_1.dat OneObject-i100000-316.hdf5.dat \
    OneObject-i100000-499.hdf5.dat OneObject-i1028-138.hdf5.dat RockPile_tob1.dat Rover1039.dat \
    Rover1040.dat Rover1041.dat Rover11035.dat Rover11211.dat Rover3865.dat Rover4144.dat \
    Rover4396.dat Rover4493.dat Rover4516.dat Rover4609.dat Rover4613.dat Rover4622.dat \
    Rover9770.dat fc2d_granularflowonwall_00667_00000.dat fc2d_granularflowonwall_02020_00213.dat \
    fc2d_granularflowonwall_07002_00801.dat; do
    [ -s "$dir/$f" ] || curl -sSfL "$base/$f" -o "$dir/$f"
done
ls "$dir" | wc -l
