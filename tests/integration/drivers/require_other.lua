-- Loads another driver's file: require finds the shipped library only, whatever package.path
-- says; out before it drives.
package.path = "./tests/integration/drivers/?.lua;" .. package.path
return require "good"
